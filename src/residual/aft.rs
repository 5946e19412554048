//! `F_rest(Q)` by AFT (alternating frequency/time), element by element: the local harmonics
//! `U_k = w·Q_k` of every active element are synthesised to `u(θ_j)`, `u̇(θ_j)` at the N
//! samples, the rest `f(θ, u, u̇) - f0 - k0 u - d0 u̇` is evaluated there (a sample on a time
//! jump takes the mean of both one-sided limits, crossed kinks are corrected, see
//! [`crate::harmonic::kinks`]) and an FFT brings it back, `F_rest += w F_k`. With a Jacobian,
//! the samples of `∂f/∂u`, `∂f/∂u̇` give the exact block `(w wᵀ) ⊗ L_e` (see
//! [`crate::jacobian`]). Laws with memory are marched instead (`memory`).

use super::{AftBuffers, HarmonicBalance};
use crate::error::Result;
use crate::harmonic::HarmonicBasis;
use crate::model::Model;
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// `w·x` over the unknowns of `weights`.
#[inline]
pub(super) fn gather(weights: &[(usize, f64)], x: &[Complex64]) -> Complex64 {
    weights
        .iter()
        .fold(Complex64::default(), |acc, &(i, w)| acc + x[i] * w)
}

/// `out += w f` over the unknowns of `weights`.
#[inline]
pub(super) fn scatter_add(weights: &[(usize, f64)], f: Complex64, out: &mut [Complex64]) {
    for &(i, w) in weights {
        out[i] += f * w;
    }
}

/// A time-varying or nonlinear element, the law the AFT evaluates for it (its band-limited
/// copy where it has one, see [`ForceLaw::band_limited`](crate::force::ForceLaw::band_limited))
/// and the samples that sit on its time jumps.
#[derive(Debug, Clone)]
pub(super) struct ActiveElement {
    pub(super) index: usize,
    /// `u = Σ w_i x_i` over the unknowns (the DOFs, or the element coordinates).
    pub(super) weights: Vec<(usize, f64)>,
    pub(super) band_limited: Option<std::sync::Arc<dyn crate::force::ForceLaw>>,
    pub(super) jump_samples: Vec<usize>,
    /// The law's kinks in `u`, whose crossings the quadrature corrects.
    pub(super) kinks: Vec<f64>,
    /// Whether the law (its own, not the band-limited copy) is affine on its pieces, so that
    /// its harmonics are exact across its kinks (`exact_kinks`).
    pub(super) exact_pieces: bool,
    /// The law's time jumps as angles on the fundamental, `(b + 2πr)/ν`.
    pub(super) time_breaks: Vec<f64>,
}

impl ActiveElement {
    /// The active elements of `model` on `basis` (those not linear and time-invariant), with
    /// their band-limited laws, time-jump samples and kinks.
    pub(super) fn of_model(model: &Model, basis: &HarmonicBasis) -> Vec<Self> {
        let (samples, h, nu) = (basis.samples(), basis.harmonics(), basis.subharmonic());
        // Time-varying coefficients keep the orders of θ up to 2H/ν (all of them alias-free
        // with N >= 4H + 1; fewer when N is forced lower).
        let band = if samples > 4 * h {
            2 * h
        } else {
            samples.saturating_sub(2 * h + 1).max(h / 2)
        } / nu;
        model
            .elements()
            .iter()
            .enumerate()
            .filter(|(_, e)| !e.law().is_linear_time_invariant())
            .map(|(index, e)| {
                let band_limited: Option<std::sync::Arc<dyn crate::force::ForceLaw>> =
                    e.law().band_limited(samples, band).map(Into::into);
                let law = band_limited.as_deref().unwrap_or(e.law());
                let mut jump_samples: Vec<usize> = law
                    .time_breakpoints()
                    .iter()
                    .flat_map(|&b| (0..nu).map(move |r| (b + TAU * r as f64) / nu as f64))
                    .filter_map(|b| {
                        let x = b / TAU * samples as f64;
                        let j = x.round();
                        ((x - j).abs() < 1e-9).then_some(j as usize % samples)
                    })
                    .collect();
                jump_samples.sort_unstable();
                jump_samples.dedup();
                let own = e.law();
                let time_breaks: Vec<f64> = own
                    .time_breakpoints()
                    .iter()
                    .filter(|b| b.is_finite())
                    .flat_map(|&b| (0..nu).map(move |r| (b + TAU * r as f64) / nu as f64))
                    .collect();
                let kinks = own.kinks();
                let reach = kinks.iter().fold(1.0_f64, |m, k| m.max(4.0 * k.abs()));
                let exact_pieces = !kinks.is_empty()
                    && own.memory().is_none()
                    && crate::force::affine::affine_law(own, reach, 1.0);
                // A law with memory is marched (no kink quadrature, no time jumps).
                if law.memory().is_some() {
                    jump_samples.clear();
                }
                ActiveElement {
                    index,
                    weights: e.weights().to_vec(),
                    kinks: if law.memory().is_some() {
                        Vec::new()
                    } else {
                        law.kinks()
                    },
                    band_limited,
                    jump_samples,
                    exact_pieces,
                    time_breaks,
                }
            })
            .collect()
    }
}

impl HarmonicBalance<'_> {
    /// `out ← F_rest(Q)` by AFT (use [`Workspace::aft_buffers`](super::Workspace::aft_buffers) for `ws`). Error if a force turns non-finite (names the element).
    pub fn rest_into(
        &self,
        q: &[Complex64],
        out: &mut [Complex64],
        ws: &mut AftBuffers,
    ) -> Result<()> {
        self.aft_into(q, out, None, ws)
    }

    /// `out ← F_rest(Q)`, and, if `jac` is given, `jac += ∂F_rest/∂x` in the real layout
    /// ([`RealLayout`](crate::harmonic::RealLayout)): per element `(w wᵀ) ⊗ L_e`, with `L_e`
    /// the exact derivative of the AFT (see [`crate::jacobian`]), from the same samples.
    pub fn aft_into(
        &self,
        q: &[Complex64],
        out: &mut [Complex64],
        mut jac: Option<&mut DMatrix<f64>>,
        ws: &mut AftBuffers,
    ) -> Result<()> {
        let (n, h) = (self.n, self.basis.harmonics());
        let omega = self.basis.fundamental();
        out.fill(Complex64::default());
        for act in &self.active {
            let e = &self.model.elements()[act.index];
            self.element_samples(act, q, ws);
            let law = self.law(act);
            let lin = e.linear_part();
            if let Some(m) = law.memory() {
                self.memory_rest(act, m, &lin, out, jac.as_deref_mut(), ws)?;
                continue;
            }
            law.force_batch(&self.thetas, &ws.u, &ws.du, &mut ws.f);
            for ((f, &u), &du) in ws.f.iter_mut().zip(&ws.u).zip(&ws.du) {
                *f -= lin.offset + lin.stiffness * u + lin.damping * du;
            }
            // A sample on a time jump takes the mean of both one-sided limits.
            let delta = 1e-7 * TAU / self.basis.samples() as f64;
            for &j in &act.jump_samples {
                let (t, u, du) = (self.thetas[j], ws.u[j], ws.du[j]);
                let mean = 0.5 * (law.force(t - delta, u, du) + law.force(t + delta, u, du));
                ws.f[j] = mean - lin.offset - lin.stiffness * u - lin.damping * du;
            }
            ws.force_evaluations += self.basis.samples() + 2 * act.jump_samples.len();
            self.samples(ws).check("force", e.name(), &ws.f)?;
            // Contact edges crossed between samples: exact harmonics for a law affine on its
            // pieces, else the trapezoid error corrected (see [`crate::harmonic::kinks`]), from
            // the local harmonics still in `uk`.
            ws.crossings.clear();
            ws.edges.clear();
            let mut exact = false;
            if !act.kinks.is_empty() {
                let kinks = &crate::harmonic::kinks::find_edge_crossings;
                kinks(&act.kinks, &ws.u, &ws.du, &ws.uk, omega, &mut ws.edges);
                exact = act.exact_pieces
                    && !ws.edges.is_empty()
                    && self.exact_kinks_into(act, e.law(), &lin, ws);
                if exact {
                    ws.exact_contacts += 1;
                } else {
                    ws.approximate_contacts += usize::from(!ws.edges.is_empty());
                    crate::harmonic::kinks::crossing_jumps(
                        law,
                        &ws.edges,
                        &ws.uk,
                        omega,
                        self.basis.subharmonic(),
                        self.basis.samples(),
                        &mut ws.crossings,
                    );
                    ws.force_evaluations += 12 * ws.crossings.len();
                }
            }
            if !exact {
                self.aft.analyze_into(&mut ws.f, &mut ws.uk, &mut ws.aft);
                ws.ffts += 3;
                crate::harmonic::kinks::correct_harmonics(
                    &mut ws.uk,
                    self.basis.samples(),
                    &ws.crossings,
                );
            } else {
                ws.ffts += 2;
            }
            for k in 0..=h {
                scatter_add(&act.weights, ws.uk[k], &mut out[k * n..(k + 1) * n]);
            }
            if let Some(jac) = jac.as_deref_mut() {
                if !exact {
                    self.element_spectra(act, &lin, e.name(), ws)?;
                }
                crate::jacobian::add_element_jacobian(
                    &ws.spec_u,
                    &ws.spec_du,
                    self.basis.samples(),
                    h,
                    omega,
                    &act.weights,
                    n,
                    jac,
                    &mut ws.jac_scratch,
                );
            }
        }
        // The coupling through the harmonics above H (not in the Jacobian, see `tail`).
        if let Some(tail) = self.tail.as_deref().filter(|t| t.applies()) {
            tail.add_into(self, q, out, ws);
        }
        Ok(())
    }

    /// The spectra of `∂f/∂u - k0`, `∂f/∂u̇ - d0` of `act` from its samples into `ws.spec_u`,
    /// `ws.spec_du`, corrected at the crossings in `ws.crossings`.
    fn element_spectra(
        &self,
        act: &ActiveElement,
        lin: &crate::force::LinearPart,
        name: &str,
        ws: &mut AftBuffers,
    ) -> Result<()> {
        self.derivative_samples(act, ws);
        for (g, d) in ws.gu.iter_mut().zip(ws.gdu.iter_mut()) {
            *g -= lin.stiffness;
            *d -= lin.damping;
        }
        let samples = self.samples(ws);
        samples.check("force derivative ∂f/∂u", name, &ws.gu)?;
        samples.check("force derivative ∂f/∂u̇", name, &ws.gdu)?;
        self.aft
            .spectrum_into(&mut ws.gu, &mut ws.spec_u, &mut ws.aft);
        self.aft
            .spectrum_into(&mut ws.gdu, &mut ws.spec_du, &mut ws.aft);
        ws.ffts += 2;
        let samples = self.basis.samples();
        let correct = crate::harmonic::kinks::correct_spectrum;
        correct(&mut ws.spec_u, samples, &ws.crossings, false);
        correct(&mut ws.spec_du, samples, &ws.crossings, true);
        Ok(())
    }

    /// The law the AFT evaluates for `act`.
    pub(super) fn law<'a>(&'a self, act: &'a ActiveElement) -> &'a dyn crate::force::ForceLaw {
        act.band_limited
            .as_deref()
            .unwrap_or(self.model.elements()[act.index].law())
    }

    /// `u(θ_j)`, `u̇(θ_j)` of element `e` at the samples into `b.u`, `b.du` (its local
    /// harmonics `U_k = w·Q_k` in `b.uk`).
    pub(super) fn element_samples(&self, act: &ActiveElement, q: &[Complex64], b: &mut AftBuffers) {
        let (n, omega) = (self.n, self.basis.fundamental());
        for (k, uk) in b.uk.iter_mut().enumerate() {
            *uk = gather(&act.weights, &q[k * n..(k + 1) * n]);
        }
        self.aft
            .synthesize_into(&b.uk, |_| Complex64::new(1.0, 0.0), &mut b.u, &mut b.aft);
        self.aft.synthesize_into(
            &b.uk,
            |k| Complex64::new(0.0, k as f64 * omega),
            &mut b.du,
            &mut b.aft,
        );
    }

    /// `∂f/∂u`, `∂f/∂u̇` at the samples into `b.gu`, `b.gdu`; a sample on a time jump takes the
    /// mean of both one-sided limits, as the force does.
    pub(super) fn derivative_samples(&self, act: &ActiveElement, b: &mut AftBuffers) {
        let law = self.law(act);
        law.derivatives_batch(&self.thetas, &b.u, &b.du, &mut b.gu, &mut b.gdu);
        let delta = 1e-7 * TAU / self.basis.samples() as f64;
        for &j in &act.jump_samples {
            let (t, u, du) = (self.thetas[j], b.u[j], b.du[j]);
            let (a0, b0) = law.derivatives(t - delta, u, du);
            let (a1, b1) = law.derivatives(t + delta, u, du);
            (b.gu[j], b.gdu[j]) = (0.5 * (a0 + a1), 0.5 * (b0 + b1));
        }
    }
}
