//! The harmonic-balance problem: `R(Q) = Z(Ω) Q + F_rest(Q) - F_split = 0`.
//!
//! For every harmonic `k`, `Z_k = -(kΩ)² M + i kΩ D0 + K0` is the paper's dynamic stiffness
//! (eq. 2) with the constant split `K0`, `D0` ([`Model::k0`], [`Model::d0`]). The rest
//! `F_rest(Q)` collects, per element, `w (f(θ, u, u̇) - f0 - k0 u - d0 u̇)` with `u = w·q`, and
//! `F_split = F_ext - Σ w f0` (the static offsets `f0` of the linear parts moved to the load side,
//! so the first, linear iterate already sits on an engaged contact): the paper's
//! `D1(t) q̇ + K1(t) q` and any nonlinearity. It is evaluated by AFT: the element's local
//! harmonics `U_k = w·Q_k` are synthesised to `u(θ_j)`, `u̇(θ_j)` at the N samples, the force is
//! evaluated there, and an FFT brings it back (three real FFTs per time-varying element,
//! whatever the number of DOFs). Elements that are linear and time-invariant cost nothing.

use crate::error::{Error, Result};
use crate::harmonic::{AftPlan, AftScratch, DynamicStiffness, HarmonicBasis, Part, RealLayout};
use crate::linear::Formulation;
use crate::model::Model;

mod condensed;
mod limits;
mod located;
mod memory;
use crate::solution::SolveStats;
pub use limits::{estimate_bytes, MAX_SYSTEM_BYTES};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// `out += w f` over the unknowns of `weights`.
#[inline]
fn scatter_add(weights: &[(usize, f64)], f: Complex64, out: &mut [Complex64]) {
    for &(i, w) in weights {
        out[i] += f * w;
    }
}

/// `Z_k` of a free-free model: `Z_0 = K0 + s M R Rᵀ M` (see [`crate::model::rigid`]).
fn free_dynamic_stiffness(
    basis: &HarmonicBasis,
    dense: &crate::model::DenseMatrices,
    rigid: &crate::model::RigidModes,
) -> Result<DynamicStiffness> {
    DynamicStiffness::with_static_augmentation(
        basis,
        &dense.mass,
        &dense.d0,
        &dense.k0,
        Some(&rigid.augmentation()),
    )
}

/// A model discretised on a harmonic basis: AFT plan, factored `Z_k`, load harmonics.
///
/// Build it once per (model, Ω, H, N) and reuse it for any number of solves; every solve needs
/// a [`Workspace`] from [`HarmonicBalance::workspace`].
#[derive(Debug)]
pub struct HarmonicBalance<'m> {
    model: &'m Model,
    basis: HarmonicBasis,
    aft: AftPlan,
    z: DynamicStiffness,
    f_ext: Vec<Complex64>,
    /// `F_ext - Σ w f0`: the load seen by the split (offsets of the linear parts moved over).
    f_split: Vec<Complex64>,
    /// Dense M, D0, K0 of the full formulation (none when condensed).
    dense: Option<Box<crate::model::DenseMatrices>>,
    active: Vec<ActiveElement>,
    thetas: Vec<f64>,
    /// Unknowns per harmonic: n DOFs, or m element coordinates when condensed.
    n: usize,
    /// Their names.
    names: Vec<String>,
    /// The condensation onto the element coordinates, with the full `F_split` it recovers
    /// `Q` from (see [`crate::linear::condensation`]).
    condensed: Option<Box<(crate::linear::Condensation, Vec<Complex64>)>>,
    /// Rigid-body modes of a free-free model (full formulation: `Z_0 = K0 + s M R Rᵀ M`).
    rigid: Option<std::sync::Arc<crate::model::RigidModes>>,
    /// `cos`, `sin` of `2π m / N` for the Jacobian of laws with memory (empty without them).
    trig: Vec<(f64, f64)>,
}

/// A time-varying or nonlinear element, the law the AFT evaluates for it (its band-limited
/// copy where it has one, see [`ForceLaw::band_limited`](crate::force::ForceLaw::band_limited))
/// and the samples that sit on its time jumps.
#[derive(Debug, Clone)]
struct ActiveElement {
    index: usize,
    /// `u = Σ w_i x_i` over the unknowns (the DOFs, or the element coordinates).
    weights: Vec<(usize, f64)>,
    band_limited: Option<std::sync::Arc<dyn crate::force::ForceLaw>>,
    jump_samples: Vec<usize>,
    /// The law's kinks in `u`, whose crossings the quadrature corrects.
    kinks: Vec<f64>,
}

/// Buffers of one AFT pass and its work counters.
#[derive(Debug, Clone)]
pub struct AftBuffers {
    aft: AftScratch,
    uk: Vec<Complex64>,
    u: Vec<f64>,
    du: Vec<f64>,
    f: Vec<f64>,
    gu: Vec<f64>,
    gdu: Vec<f64>,
    spec_u: Vec<Complex64>,
    spec_du: Vec<Complex64>,
    jac_scratch: crate::jacobian::JacobianScratch,
    crossings: Vec<crate::harmonic::kinks::Crossing>,
    /// Sensitivities of the march of laws with memory (empty without them).
    march: crate::harmonic::march::MarchBuffers,
    /// One local Jacobian column (laws with memory).
    column: Vec<f64>,
    /// Real FFTs done so far.
    pub ffts: usize,
    /// Force-law calls so far.
    pub force_evaluations: usize,
}

/// Per-solve buffers: no allocation happens while iterating.
#[derive(Debug, Clone)]
pub struct Workspace {
    pub(crate) eval: AftBuffers,
    pub(crate) q: Vec<Complex64>,
    pub(crate) rest: Vec<Complex64>,
    pub(crate) rhs: Vec<Complex64>,
    pub(crate) zq: Vec<Complex64>,
    pub(crate) stats: SolveStats,
}

impl Workspace {
    /// The AFT buffers, for calling [`HarmonicBalance::rest_into`] directly.
    pub fn aft_buffers(&mut self) -> &mut AftBuffers {
        &mut self.eval
    }
}

impl<'m> HarmonicBalance<'m> {
    /// Discretises `model` on `basis`: plans the FFTs, factors `Z_k` for `k = 0..=H`.
    ///
    /// Errors: a load order or an element's time order (a mesh order) above H (unless H = 0, a
    /// static analysis), or a singular `Z_k` (undamped resonance at a harmonic, or a
    /// rigid-body mode at k = 0).
    pub fn new(model: &'m Model, basis: HarmonicBasis) -> Result<Self> {
        Self::with_formulation(model, basis, Formulation::Full)
    }

    /// [`HarmonicBalance::new`] in the given formulation: the full one (n DOFs per harmonic)
    /// or the exact condensation onto the element coordinates (m per harmonic; solutions
    /// still come back with all n DOFs).
    pub fn with_formulation(
        model: &'m Model,
        basis: HarmonicBasis,
        formulation: Formulation,
    ) -> Result<Self> {
        let (n, h) = (model.n_dofs(), basis.harmonics());
        if basis.samples() < 2 * h + 1 {
            return Err(Error::TooFewSamples {
                harmonics: h,
                samples: basis.samples(),
            });
        }
        limits::check_size(model, &basis, formulation)?;
        let mut f_ext = vec![Complex64::default(); (h + 1) * n];
        let nu = basis.subharmonic();
        for l in model.loads() {
            // Order k of the shaft is harmonic νk of the fundamental Ω/ν.
            if l.order.saturating_mul(nu) > h {
                return Err(Error::LoadOrderTooHigh {
                    dof: model.dof_names()[l.dof].clone(),
                    order: l.order,
                    harmonics: h / nu,
                });
            }
            f_ext[l.order * nu * n + l.dof] += crate::harmonic::from_cos_sin(l.cos, l.sin);
        }
        // H = 0 is a static analysis by choice; otherwise every time variation must fit.
        for e in model.elements().iter().filter(|_| h > 0) {
            if let Some(order) = e.law().time_order() {
                if order.saturating_mul(nu) > h {
                    return Err(Error::ElementOrderTooHigh {
                        element: e.name().to_string(),
                        order,
                        harmonics: h / nu,
                    });
                }
            }
        }
        let mut f_split = f_ext.clone();
        for e in model.elements() {
            e.scatter_add(
                Complex64::new(-e.linear_part().offset, 0.0),
                &mut f_split[..n],
            );
        }
        let samples = basis.samples();
        // The laws see the shaft angle Ωt = ν θ_j.
        let thetas: Vec<f64> = (0..samples).map(|j| basis.shaft_angle(j)).collect();
        // Time-varying coefficients keep the orders of θ up to 2H/ν (all of them alias-free
        // with N >= 4H + 1; fewer when N is forced lower).
        let h = basis.harmonics();
        let band = if samples > 4 * h {
            2 * h
        } else {
            samples.saturating_sub(2 * h + 1).max(h / 2)
        } / nu;
        let active = model
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
                }
            })
            .collect::<Vec<ActiveElement>>();
        let has_memory = active
            .iter()
            .any(|a| model.elements()[a.index].law().memory().is_some());
        let mut hb = Self {
            model,
            basis,
            aft: AftPlan::new(basis),
            z: DynamicStiffness::empty(),
            f_ext,
            f_split,
            dense: None,
            active,
            thetas,
            n,
            names: model.dof_names().to_vec(),
            condensed: None,
            rigid: None,
            trig: if has_memory {
                memory::trig_table(samples)
            } else {
                Vec::new()
            },
        };
        let mean_load: Vec<f64> = hb.f_ext[..n].iter().map(|v| v.re).collect();
        match formulation.resolve(model) {
            Formulation::Full | Formulation::Auto => hb.factor_full(&mean_load)?,
            Formulation::Condensed => {
                match hb.condense() {
                    // `auto` falls back to the full formulation where the coordinates are
                    // linearly dependent (a split power path closes a loop of meshes).
                    Err(Error::Solver { reason })
                        if formulation == Formulation::Auto
                            && n <= Model::MAX_DENSE_DOFS
                            && reason.contains("linearly dependent") =>
                    {
                        return Self::with_formulation(model, basis, Formulation::Full);
                    }
                    r => r?,
                }
                hb.rigid = hb
                    .condensed
                    .as_ref()
                    .and_then(|c| c.0.rigid_modes().cloned());
                if let Some(rigid) = &hb.rigid {
                    rigid.check_balance(model, &mean_load)?;
                }
            }
        }
        Ok(hb)
    }

    /// The rigid-body modes of a free-free model, whose static part is solved in their
    /// complement with the mean rigid angle `Rᵀ M q_0 = 0` (see [`crate::model::rigid`]);
    /// `None` for a grounded model.
    pub fn rigid_modes(&self) -> Option<&crate::model::RigidModes> {
        self.rigid.as_deref()
    }

    /// The model.
    pub fn model(&self) -> &'m Model {
        self.model
    }

    /// The harmonic basis.
    pub fn basis(&self) -> &HarmonicBasis {
        &self.basis
    }

    /// The AFT plan.
    pub fn aft(&self) -> &AftPlan {
        &self.aft
    }

    /// The factored dynamic stiffness.
    pub fn dynamic_stiffness(&self) -> &DynamicStiffness {
        &self.z
    }

    /// Load harmonics `F_ext` ((H+1)·n, harmonic-major).
    pub fn external_load(&self) -> &[Complex64] {
        &self.f_ext
    }

    /// The load of the split, `F_ext - Σ_e w_e f0_e`: with it, `R = Z Q + F_rest(Q) - F_split`
    /// where `F_rest` is evaluated without the offsets `f0` of the linear parts.
    pub fn split_load(&self) -> &[Complex64] {
        &self.f_split
    }

    /// Length of a harmonic vector, (H+1)·n.
    pub fn len(&self) -> usize {
        (self.basis.harmonics() + 1) * self.n
    }

    /// `true` if there are no unknowns (never: a model has at least one DOF).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Buffers for one solve at a time.
    pub fn workspace(&self) -> Workspace {
        let (h, n, s) = (self.basis.harmonics(), self.n, self.basis.samples());
        let len = (h + 1) * n;
        Workspace {
            eval: AftBuffers {
                aft: self.aft.make_scratch(),
                uk: vec![Complex64::default(); h + 1],
                u: vec![0.0; s],
                du: vec![0.0; s],
                f: vec![0.0; s],
                gu: vec![0.0; s],
                gdu: vec![0.0; s],
                spec_u: vec![Complex64::default(); s / 2 + 1],
                spec_du: vec![Complex64::default(); s / 2 + 1],
                jac_scratch: crate::jacobian::JacobianScratch::new(h),
                crossings: Vec::with_capacity(16),
                march: if self.trig.is_empty() {
                    Default::default()
                } else {
                    crate::harmonic::march::MarchBuffers::new(s, 2 * h + 1)
                },
                column: vec![0.0; if self.trig.is_empty() { 0 } else { 2 * h + 1 }],
                ffts: 0,
                force_evaluations: 0,
            },
            q: vec![Complex64::default(); len],
            rest: vec![Complex64::default(); len],
            rhs: vec![Complex64::default(); len],
            zq: vec![Complex64::default(); len],
            stats: SolveStats::default(),
        }
    }

    /// `out ← F_rest(Q)` by AFT (use [`Workspace::aft_buffers`] for `ws`). Error if a force turns non-finite (names the element).
    pub fn rest_into(
        &self,
        q: &[Complex64],
        out: &mut [Complex64],
        ws: &mut AftBuffers,
    ) -> Result<()> {
        self.aft_into(q, out, None, ws)
    }

    /// `out ← F_rest(Q)`, and, if `jac` is given, `jac += ∂F_rest/∂x` in the real layout
    /// ([`RealLayout`]): per element `(w wᵀ) ⊗ L_e`, with `L_e` the exact derivative of the AFT
    /// (see [`crate::jacobian`]), from the same samples.
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
            // Contact edges crossed between samples: the trapezoid error, from the local
            // harmonics still in `uk` (see [`crate::harmonic::kinks`]).
            ws.crossings.clear();
            if !act.kinks.is_empty() {
                crate::harmonic::kinks::find_crossings(
                    law,
                    &act.kinks,
                    &ws.u,
                    &ws.du,
                    &ws.uk,
                    omega,
                    self.basis.subharmonic(),
                    &mut ws.crossings,
                );
                ws.force_evaluations += 12 * ws.crossings.len();
            }
            self.aft.analyze_into(&mut ws.f, &mut ws.uk, &mut ws.aft);
            ws.ffts += 3;
            crate::harmonic::kinks::correct_harmonics(
                &mut ws.uk,
                self.basis.samples(),
                &ws.crossings,
            );
            for k in 0..=h {
                scatter_add(&act.weights, ws.uk[k], &mut out[k * n..(k + 1) * n]);
            }
            if let Some(jac) = jac.as_deref_mut() {
                self.derivative_samples(act, ws);
                for (g, d) in ws.gu.iter_mut().zip(ws.gdu.iter_mut()) {
                    *g -= lin.stiffness;
                    *d -= lin.damping;
                }
                let samples = self.samples(ws);
                samples.check("force derivative ∂f/∂u", e.name(), &ws.gu)?;
                samples.check("force derivative ∂f/∂u̇", e.name(), &ws.gdu)?;
                self.aft
                    .spectrum_into(&mut ws.gu, &mut ws.spec_u, &mut ws.aft);
                self.aft
                    .spectrum_into(&mut ws.gdu, &mut ws.spec_du, &mut ws.aft);
                ws.ffts += 2;
                let samples = self.basis.samples();
                crate::harmonic::kinks::correct_spectrum(
                    &mut ws.spec_u,
                    samples,
                    &ws.crossings,
                    false,
                );
                crate::harmonic::kinks::correct_spectrum(
                    &mut ws.spec_du,
                    samples,
                    &ws.crossings,
                    true,
                );
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
        Ok(())
    }

    /// `out ← ∂R/∂Ω` at `x` (real layout), analytic: `(dZ_k/dΩ) Q_k` with
    /// `dZ_k/dΩ = -2(k/ν)²Ω M + i (k/ν) D0` (harmonic k oscillates at kΩ/ν), plus the AFT of `(∂f/∂u̇ - d0) u̇/Ω` per element (the rest
    /// depends on Ω only through `u̇ = Σ i kΩ U_k e^{ikθ}`). For continuation in Ω.
    pub fn omega_derivative_real_into(
        &self,
        x: &[f64],
        out: &mut [f64],
        ws: &mut Workspace,
    ) -> Result<()> {
        let layout = self.layout();
        let (n, h) = (layout.n, layout.h);
        let omega = self.basis.omega();
        layout.unpack(x, &mut ws.q);
        if let Some(b) = self.condensed.as_deref() {
            let (cond, f_full) = (&b.0, &b.1);
            cond.omega_derivative(
                &self.z,
                &self.f_split,
                f_full,
                &ws.q,
                self.basis.subharmonic(),
                omega,
                &mut ws.rhs,
            );
        } else {
            self.dense_omega_derivative(&mut ws.rhs, &ws.q)?;
        }
        let b = &mut ws.eval;
        for act in &self.active {
            let e = &self.model.elements()[act.index];
            self.element_samples(act, &ws.q, b);
            if let Some(m) = self.law(act).memory() {
                self.memory_omega_derivative(act, m, b)?;
            } else {
                self.derivative_samples(act, b);
                let d0 = e.linear_part().damping;
                for ((f, g), du) in b.f.iter_mut().zip(&b.gdu).zip(&b.du) {
                    *f = (g - d0) * du / omega;
                }
            }
            self.samples(b).check("Ω-derivative", e.name(), &b.f)?;
            self.aft.analyze_into(&mut b.f, &mut b.uk, &mut b.aft);
            b.ffts += 3;
            for k in 0..=h {
                scatter_add(&act.weights, b.uk[k], &mut ws.rhs[k * n..(k + 1) * n]);
            }
        }
        layout.pack(&ws.rhs, out);
        Ok(())
    }

    /// `rhs ← (dZ_k/dΩ) Q_k` with the dense M, D0 of the full formulation.
    fn dense_omega_derivative(&self, rhs: &mut [Complex64], q: &[Complex64]) -> Result<()> {
        let Some(dense) = self.dense.as_deref() else {
            return Err(Error::Solver {
                reason: "no dense matrices for the Ω-derivative".into(),
            });
        };
        let (n, h) = (self.n, self.basis.harmonics());
        let omega = self.basis.omega();
        let nu = self.basis.subharmonic() as f64;
        let m = &dense.mass;
        for k in 0..=h {
            let kf = k as f64 / nu;
            for i in 0..n {
                let mut acc = Complex64::default();
                for j in 0..n {
                    let dz =
                        Complex64::new(-2.0 * kf * kf * omega * m[(i, j)], kf * dense.d0[(i, j)]);
                    acc += dz * q[k * n + j];
                }
                rhs[k * n + i] = acc;
            }
        }
        Ok(())
    }

    /// Builds and factors the dense `Z_k` of the full formulation (with the static
    /// augmentation of a free-free model, whose mean loads must balance).
    fn factor_full(&mut self, mean_load: &[f64]) -> Result<()> {
        let (model, basis) = (self.model, self.basis);
        let dense = model.dense("full formulation")?;
        self.z = match DynamicStiffness::new(&basis, &dense.mass, &dense.d0, &dense.k0) {
            Err(e @ Error::SingularDynamicStiffness { harmonic: 0, .. }) => {
                let Some(rigid) = crate::model::rigid::find_dense(model, &dense) else {
                    return Err(e);
                };
                rigid.check_balance(model, mean_load)?;
                let z = free_dynamic_stiffness(&basis, &dense, &rigid)?;
                self.rigid = Some(std::sync::Arc::new(rigid));
                z
            }
            z => z?,
        };
        self.dense = Some(Box::new(dense));
        Ok(())
    }

    /// Multiplies the alternating load (harmonics `k >= 1` of `F_ext`) by `factor`; the static
    /// load stays. For a homotopy in the load amplitude.
    pub fn scale_alternating_load(&mut self, factor: f64) {
        let n = self.n;
        for v in self.f_ext[n..]
            .iter_mut()
            .chain(self.f_split[n..].iter_mut())
        {
            *v *= factor;
        }
        // The condensed formulation recovers all DOFs from the full load: scale it alike.
        let n_full = self.model.n_dofs();
        if let Some(b) = self.condensed.as_mut() {
            for v in b.1[n_full..].iter_mut() {
                *v *= factor;
            }
        }
    }

    /// Moves the discretisation to a new fundamental Ω (rebuilds and factors `Z_k`); for
    /// sweeps. Errors as [`HarmonicBalance::new`] on a singular `Z_k`.
    pub fn set_omega(&mut self, omega: f64) -> Result<()> {
        let basis = self.basis.with_omega(omega)?;
        if self.condensed.is_some() {
            self.basis = basis;
            return self.condense();
        }
        let Some(dense) = self.dense.as_deref() else {
            return Err(Error::Solver {
                reason: "no dense matrices for the full formulation".into(),
            });
        };
        self.z = match &self.rigid {
            Some(rigid) => free_dynamic_stiffness(&basis, dense, rigid)?,
            None => DynamicStiffness::new(&basis, &dense.mass, &dense.d0, &dense.k0)?,
        };
        self.basis = basis;
        Ok(())
    }

    /// The law the AFT evaluates for `act`.
    fn law<'a>(&'a self, act: &'a ActiveElement) -> &'a dyn crate::force::ForceLaw {
        act.band_limited
            .as_deref()
            .unwrap_or(self.model.elements()[act.index].law())
    }

    /// `u(θ_j)`, `u̇(θ_j)` of element `e` at the samples into `b.u`, `b.du` (its local
    /// harmonics `U_k = w·Q_k` in `b.uk`).
    fn element_samples(&self, act: &ActiveElement, q: &[Complex64], b: &mut AftBuffers) {
        let (n, omega) = (self.n, self.basis.fundamental());
        for (k, uk) in b.uk.iter_mut().enumerate() {
            *uk = act
                .weights
                .iter()
                .fold(Complex64::default(), |acc, &(i, w)| acc + q[k * n + i] * w);
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
    fn derivative_samples(&self, act: &ActiveElement, b: &mut AftBuffers) {
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

    /// The real layout of the unknowns.
    pub fn layout(&self) -> RealLayout {
        RealLayout {
            n: self.n,
            h: self.basis.harmonics(),
        }
    }

    /// Fused residual and Jacobian in the real layout: `r ← R(x)`, and if `jac` is given,
    /// `jac ← ∂R/∂x = Z ⊕ ∂F_rest/∂x` (the block `[[A, B], [-B, A]]` of
    /// `Z_k = A + iB` for every harmonic, plus the AFT part). Both come from one AFT pass.
    pub fn residual_real_into(
        &self,
        x: &[f64],
        r: &mut [f64],
        mut jac: Option<&mut DMatrix<f64>>,
        ws: &mut Workspace,
    ) -> Result<()> {
        let layout = self.layout();
        layout.unpack(x, &mut ws.q);
        if let Some(j) = jac.as_deref_mut() {
            j.fill(0.0);
        }
        self.aft_into(&ws.q, &mut ws.rest, jac.as_deref_mut(), &mut ws.eval)?;
        let n = layout.n;
        for k in 0..=layout.h {
            let s = k * n..(k + 1) * n;
            self.z.apply(k, &ws.q[s.clone()], &mut ws.zq[s.clone()]);
            for i in s {
                ws.rhs[i] = ws.zq[i] + ws.rest[i] - self.f_split[i];
            }
        }
        layout.pack(&ws.rhs, r);
        if let Some(j) = jac {
            self.add_dynamic_stiffness_real(j);
        }
        Ok(())
    }

    /// `jac += Z` in the real layout: the block `[[A, B], [-B, A]]` of `Z_k = A + iB` per
    /// harmonic (`K0` alone at k = 0).
    pub fn add_dynamic_stiffness_real(&self, jac: &mut DMatrix<f64>) {
        let layout = self.layout();
        let n = layout.n;
        for k in 0..=layout.h {
            let z = self.z.matrix(k);
            let ca = RealLayout::block(k, Part::Cos) * n;
            let cb = RealLayout::block(k, Part::Sin) * n;
            for i in 0..n {
                for jj in 0..n {
                    let (a, b) = (z[(i, jj)].re, z[(i, jj)].im);
                    jac[(ca + i, ca + jj)] += a;
                    if k > 0 {
                        jac[(ca + i, cb + jj)] += b;
                        jac[(cb + i, ca + jj)] -= b;
                        jac[(cb + i, cb + jj)] += a;
                    }
                }
            }
        }
    }

    /// Parseval norm `sqrt(Σ_i [|X_0i|² + ½ Σ_k |X_ki|²])`: the RMS over one period, summed
    /// over DOFs.
    pub fn norm(&self, x: &[Complex64]) -> f64 {
        let n = self.n;
        let mut s = 0.0;
        for (idx, v) in x.iter().enumerate() {
            s += if idx < n {
                v.norm_sqr()
            } else {
                0.5 * v.norm_sqr()
            };
        }
        s.sqrt()
    }
}
