//! The tail correction: the coupling through the harmonics above H of force laws linear in
//! the state whose coefficients jump in time (a rectangular mesh stiffness).
//!
//! Split the exact (infinite) harmonic balance into the kept harmonics `Q_H` (`|k| ≤ H`) and
//! the tail `Q_T` (`|l| > H`):
//!
//! ```text
//! A_HH Q_H + A_HT Q_T = F_H,      A_TH Q_H + A_TT Q_T = F_T = 0.
//! ```
//!
//! The truncation drops `A_HT Q_T`. Where a coefficient jumps, `q̈` jumps, `Q_l` decays only
//! like `l⁻³`, and the kept harmonics are wrong by O(H⁻³). Far enough above the model's
//! dynamics `A_TT` is dominated by its diagonal `Z_l = −(lΩ)² M + i lΩ D0 + K0`, so
//! `Q_T ≈ −Z_T⁻¹ A_TH Q_H`, and the residual gains the Schur-complement term
//! `−A_HT Z_T⁻¹ A_TH Q_H`. On the coordinates `u_a = w_a·q` of the jumping elements it reads
//!
//! ```text
//! v_b,l = −Σ_a G_l[b, a] f_a,l                   (H < l ≤ L)
//! R_k  += w_b [k_b(θ) v_b + d_b(θ) v̇_b]_k        (k ≤ H)
//! ```
//!
//! with `f_a,l` the harmonics above H of the element force `k_a(θ) u_a + d_a(θ) u̇_a` of the kept
//! harmonics. The receptance `G_l = Wᵀ Z_l⁻¹ W` between the jumping elements follows the
//! expansion `Z(s)⁻¹ = −M⁻¹/s² − i M⁻¹DM⁻¹/s³ − M⁻¹(K − DM⁻¹D)M⁻¹/s⁴ + …` (`s = lΩ`):
//! `G_l ≈ −C/s² + i b/s³ + a/s⁴` with `C = Wᵀ M⁻¹ W` exact and the real `a`, `b` fitted so that
//! `G_H`, which the factors of `Z_H` give, is exact. Both products are computed exactly on a
//! grid of `N_T` samples (the power of two `≥ 10H + 2`, so `N_T > 2L + 2H` with
//! `L = (N_T − 2H − 1)/2` between 4H and 9H; the coefficients band-limited to `L + H` orders);
//! what lies beyond L is O((H/L)³) of the correction.
//!
//! The correction is weighed by how well the harmonics above H are mass-dominated, the ratio
//! `ρ = |G_H + C/s_H²| / |C/s_H²|` (Frobenius norms): fully applied for `ρ ≤ 0.3`, not at all
//! for `ρ ≥ 0.5` (H below or near a resonance, where the expansion does not hold), linearly in
//! between, so that the residual stays continuous in Ω.
//!
//! It is left out of the Newton Jacobian and of `∂R/∂Ω`. Newton (and the continuation's
//! corrector) then converge on it linearly, at the spectral radius of `J⁻¹ T` (`T` the
//! correction's operator): for the paper's two-shaft model at most 0.02 where it applies, also
//! with a hundredth of its damping (a prototype of the same algebra), so two or three more
//! steps.
//!
//! The paper's two-shaft model at 6000 rpm against the shared reference (an exact piecewise
//! solution): 2.7e-4 → 8.9e-7 at H = 32, 1.2e-5 → 1.0e-8 at H = 128.

use super::{AftBuffers, HarmonicBalance};
use crate::error::Result;
use crate::force::ForceLaw;
use crate::harmonic::{AftPlan, AftScratch, HarmonicBasis};
use crate::linear::envelope::Envelope;
use crate::model::Model;
use element::TailElement;
use num_complex::Complex64;

mod element;

/// Whether the tail correction applies to `law`: linear in the state, without memory, with
/// coefficients that jump in time.
pub(crate) fn corrects(law: &dyn ForceLaw) -> bool {
    law.is_linear_in_state() && law.memory().is_none() && !law.time_breakpoints().is_empty()
}

/// The plan, laws and receptance model of the tail correction of one [`HarmonicBalance`].
#[derive(Debug)]
pub(super) struct TailCorrection {
    /// The fine grid: L harmonics on `N_T` samples.
    plan: AftPlan,
    elements: Vec<TailElement>,
    /// `C = Wᵀ M⁻¹ W` over the jumping elements, row-major.
    mobility: Vec<f64>,
    /// At the current Ω, row-major: `C/s_H²` and `R = G_H + C/s_H²`, the rest of the exact
    /// receptance at harmonic H beyond its mass term.
    mass_h: Vec<f64>,
    rest_h: Vec<Complex64>,
    /// The weight of the correction at the current Ω: 1 where the harmonics above H are
    /// mass-dominated (`|R| ≤ 0.3 |C/s_H²|`), 0 where they are not (`≥ 0.5`), linear between,
    /// so that the residual does not jump with Ω.
    weight: f64,
    /// `r_l = H/l` at `l = H+1..=L`, the receptance model's variable (no division per
    /// evaluation; the receptance itself is formed per use, so memory stays O(L), not O(L m²)).
    ratios: Vec<f64>,
}

/// Buffers of the tail correction (empty without one).
#[derive(Debug, Clone, Default)]
pub struct TailBuffers {
    aft: Option<AftScratch>,
    uk: Vec<Complex64>,
    u: Vec<f64>,
    du: Vec<f64>,
    /// The force harmonics `0..=L` of every jumping element, element-major.
    spectra: Vec<Complex64>,
    vk: Vec<Complex64>,
}

impl TailCorrection {
    /// The correction of `hb`, or `None` where it has nothing to correct: the basis has it off
    /// or see [`TailCorrection::whatever_the_basis`].
    pub(super) fn new(hb: &HarmonicBalance) -> Result<Option<Self>> {
        if !hb.basis.tail_correction() {
            return Ok(None);
        }
        Self::whatever_the_basis(hb)
    }

    /// The correction of `hb` also where its basis has it off, or `None` where it has nothing
    /// to correct: H = 0, no active law is linear in the state with jumps and a band-limited
    /// copy, the envelope factor of M fails (a guard: models are built with M positive
    /// definite), or the fine grid would exceed the largest basis.
    pub(super) fn whatever_the_basis(hb: &HarmonicBalance) -> Result<Option<Self>> {
        let basis = hb.basis;
        let h = basis.harmonics();
        if h == 0 {
            return Ok(None);
        }
        let samples = (10 * h + 2).next_power_of_two();
        let top = (samples - 2 * h - 1) / 2;
        if top > HarmonicBasis::MAX_HARMONICS {
            return Ok(None);
        }
        let nu = basis.subharmonic();
        let fine = HarmonicBasis::new(basis.omega(), top)?
            .with_samples(samples)?
            .with_subharmonic(nu)?;
        // Coefficient orders up to (L + H)/ν of the shaft: ν·band ≤ N_T/2 − 1, alias-free.
        let band = (top + h) / nu;
        let thetas: Vec<f64> = (0..samples).map(|j| fine.shaft_angle(j)).collect();
        let elements: Vec<TailElement> = hb
            .active
            .iter()
            .enumerate()
            .filter_map(|(i, a)| {
                let law = hb.model.elements()[a.index].law();
                if !corrects(law) {
                    return None;
                }
                let law = law.band_limited(samples, band)?;
                Some(TailElement::new(i, law.as_ref(), &thetas))
            })
            .collect();
        if elements.is_empty() {
            return Ok(None);
        }
        let indices: Vec<usize> = elements.iter().map(|e| hb.active[e.active].index).collect();
        let Some(mobility) = mobility(hb.model, &indices) else {
            return Ok(None);
        };
        let mut tail = Self {
            plan: AftPlan::new(fine),
            mass_h: vec![0.0; mobility.len()],
            rest_h: vec![Complex64::default(); mobility.len()],
            mobility,
            elements,
            weight: 0.0,
            ratios: (h + 1..=top).map(|l| h as f64 / l as f64).collect(),
        };
        tail.fit(hb);
        Ok(Some(tail))
    }

    /// Fits the receptance model to the exact `G_H` of the current factors (again after a
    /// change of Ω) and weighs the correction.
    pub(super) fn fit(&mut self, hb: &HarmonicBalance) {
        let h = hb.basis.harmonics();
        let s2 = (h as f64 * hb.basis.fundamental()).powi(2);
        let m = self.elements.len();
        let mut x = vec![Complex64::default(); hb.n];
        let (mut rest, mut scale) = (0.0, 0.0);
        for b in 0..m {
            x.fill(Complex64::default());
            super::aft::scatter_add(
                &hb.active[self.elements[b].active].weights,
                Complex64::new(1.0, 0.0),
                &mut x,
            );
            hb.z.solve_in_place(h, &mut x);
            for a in 0..m {
                let g = super::aft::gather(&hb.active[self.elements[a].active].weights, &x);
                let mass = self.mobility[a * m + b] / s2;
                self.mass_h[a * m + b] = mass;
                self.rest_h[a * m + b] = g + mass;
                rest += (g + mass).norm_sqr();
                scale += mass * mass;
            }
        }
        let ratio = rest.sqrt() / scale.sqrt();
        let finite = self
            .rest_h
            .iter()
            .all(|r| r.re.is_finite() && r.im.is_finite());
        self.weight = if scale > 0.0 && ratio.is_finite() && finite {
            ((0.5 - ratio) / 0.2).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }

    /// Whether the correction is applied at the current Ω (with a positive weight).
    pub(super) fn applies(&self) -> bool {
        self.weight > 0.0
    }

    /// The receptance model at harmonic `l > H` between elements `(b, a)` (row-major index
    /// `i`): `G_l = −(C/s_H²) r² + i Im R r³ + Re R r⁴`, `r = H/l`. The terms follow the
    /// expansion `Z(s)⁻¹ = −M⁻¹/s² − i M⁻¹DM⁻¹/s³ − M⁻¹(K − DM⁻¹D)M⁻¹/s⁴ + …`, whose
    /// `s⁻³` term is imaginary and `s⁻⁴` term real for real symmetric `M`, `D`, `K`; `R`
    /// makes `G_H` exact.
    #[inline]
    fn receptance(&self, i: usize, r: f64) -> Complex64 {
        let (r2, rest) = (r * r, self.rest_h[i]);
        Complex64::new(-self.mass_h[i] * r2 + rest.re * r2 * r2, rest.im * r2 * r)
    }

    /// Buffers for [`TailCorrection::add_into`].
    pub(super) fn buffers(&self) -> TailBuffers {
        let (top, samples) = (self.plan.basis().harmonics(), self.plan.basis().samples());
        TailBuffers {
            aft: Some(self.plan.make_scratch()),
            uk: vec![Complex64::default(); top + 1],
            u: vec![0.0; samples],
            du: vec![0.0; samples],
            spectra: vec![Complex64::default(); self.elements.len() * (top + 1)],
            vk: vec![Complex64::default(); top + 1],
        }
    }

    /// `out += −A_HT Z_T⁻¹ A_TH Q` (harmonics `0..=H` of the unknowns, see the module docs).
    pub(super) fn add_into(
        &self,
        hb: &HarmonicBalance,
        q: &[Complex64],
        out: &mut [Complex64],
        ws: &mut AftBuffers,
    ) {
        let (h, n) = (hb.basis.harmonics(), hb.n);
        self.element_forces(hb, q, &mut ws.tail, |active, force| {
            let weights = &hb.active[active].weights;
            for (k, f) in force[..=h].iter().enumerate() {
                super::aft::scatter_add(weights, *f, &mut out[k * n..(k + 1) * n]);
            }
        });
        ws.ffts += 2 * self.elements.iter().map(|e| e.ffts()).sum::<usize>();
    }

    /// The force harmonics `0..=H` the tail adds to every jumping element, `each(index
    /// among the active elements, harmonics)` (the harmonics above H in the slice are not
    /// part of it).
    pub(super) fn element_forces(
        &self,
        hb: &HarmonicBalance,
        q: &[Complex64],
        tb: &mut TailBuffers,
        mut each: impl FnMut(usize, &[Complex64]),
    ) {
        let (h, n, omega) = (hb.basis.harmonics(), hb.n, hb.basis.fundamental());
        let top = self.plan.basis().harmonics();
        let m = self.elements.len();
        let Some(aft) = tb.aft.as_mut() else {
            return;
        };
        // The force harmonics above H of every jumping element, from the kept harmonics.
        for (a, te) in self.elements.iter().enumerate() {
            let weights = &hb.active[te.active].weights;
            tb.uk.fill(Complex64::default());
            for (k, uk) in tb.uk[..=h].iter_mut().enumerate() {
                *uk = super::aft::gather(weights, &q[k * n..(k + 1) * n]);
            }
            let spectrum = &mut tb.spectra[a * (top + 1)..(a + 1) * (top + 1)];
            te.force_harmonics(
                &self.plan, omega, &tb.uk, &mut tb.u, &mut tb.du, spectrum, aft,
            );
        }
        // The tail of every element's coordinate and its force on the kept harmonics.
        for (b, te) in self.elements.iter().enumerate() {
            tb.uk.fill(Complex64::default());
            for (l, &r) in (h + 1..=top).zip(&self.ratios) {
                let mut v = Complex64::default();
                for a in 0..m {
                    v -= self.receptance(b * m + a, r) * tb.spectra[a * (top + 1) + l];
                }
                tb.uk[l] = v * self.weight;
            }
            te.force_harmonics(
                &self.plan, omega, &tb.uk, &mut tb.u, &mut tb.du, &mut tb.vk, aft,
            );
            each(te.active, &tb.vk);
        }
    }
}

/// `C = Wᵀ M⁻¹ W` (row-major) over the elements `indices` of `model`, from an envelope
/// `L D Lᵀ` of M; `None` if M is singular.
fn mobility(model: &Model, indices: &[usize]) -> Option<Vec<f64>> {
    let mass = model.mass();
    let n = mass.n();
    let pattern: Vec<(usize, usize)> = mass.iter().map(|(i, j, _)| (i, j)).collect();
    let envelope = Envelope::new(n, pattern.iter().copied());
    let mut values = vec![Complex64::default(); envelope.size()];
    for (i, j, v) in mass.iter() {
        if envelope.is_lower(i, j) {
            values[envelope.position(i, j)] += v;
        }
    }
    if !envelope.factor(&mut values) {
        return None;
    }
    let m = indices.len();
    let mut x = vec![Complex64::default(); n * m];
    for (c, &e) in indices.iter().enumerate() {
        for &(i, w) in model.elements()[e].weights() {
            x[c * n + i] += w;
        }
    }
    let mut work = vec![Complex64::default(); n * m];
    envelope.solve(&values, &mut x, m, &mut work);
    let mut c = vec![0.0; m * m];
    for (a, &e) in indices.iter().enumerate() {
        for b in 0..m {
            c[a * m + b] = model.elements()[e]
                .weights()
                .iter()
                .map(|&(i, w)| w * x[b * n + i].re)
                .sum();
        }
    }
    c.iter().all(|v| v.is_finite()).then_some(c)
}
