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
//!
//! ## Files
//! The data flow, one step per file:
//! - here: the [`HarmonicBalance`] and its construction (loads `F_ext`, `F_split`, the active
//!   elements, the factored `Z_k`), its accessors;
//! - `workspace`: the per-solve buffers ([`Workspace`], [`AftBuffers`]);
//! - `aft`: `F_rest(Q)` and its exact Jacobian by AFT, element by element (`memory` for laws
//!   with memory, `exact_kinks` for laws affine on their pieces whose coordinate crosses a
//!   kink, `located` to name a non-finite sample);
//! - `real_form`: `R(x)` and `∂R/∂x` in the real layout, the Parseval norm;
//! - `frequency`: a change of Ω (`Z_k` refactored), `∂R/∂Ω`, the scaling of the alternating load;
//! - `condensed`: the condensed formulation (unknowns on the element coordinates);
//! - `tail`: the coupling through the harmonics above H of coefficients that jump in time;
//! - `limits`: the size estimate checked before anything is allocated.

use crate::error::{Error, Result};
use crate::harmonic::{AftPlan, DynamicStiffness, HarmonicBasis};
use crate::linear::Formulation;
use crate::model::Model;

mod aft;
mod condensed;
mod exact_kinks;
mod frequency;
mod limits;
mod located;
mod memory;
mod real_form;
mod speed_loads;
mod tail;
pub(crate) use tail::corrects as tail_corrects;
mod workspace;
use aft::ActiveElement;
pub use limits::{estimate_bytes, MAX_SYSTEM_BYTES};
use num_complex::Complex64;
pub use workspace::{AftBuffers, Workspace};

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
    /// The tail correction (see `tail`), where a law linear in the state jumps in time.
    tail: Option<Box<tail::TailCorrection>>,
    /// The factor on the alternating load ([`HarmonicBalance::scale_alternating_load`]).
    load_factor: f64,
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
        model.check_load_speeds(basis.omega(), basis.omega())?;
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
            let (c, s) = l.at(basis.omega());
            f_ext[l.order * nu * n + l.dof] += crate::harmonic::from_cos_sin(c, s);
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
        let active = ActiveElement::of_model(model, &basis);
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
            tail: None,
            load_factor: 1.0,
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
        hb.tail = tail::TailCorrection::new(&hb)?.map(Box::new);
        Ok(hb)
    }

    /// The rigid-body modes of a free-free model, whose static part is solved in their
    /// complement with the mean rigid angle `Rᵀ M q_0 = 0` (see [`crate::model::rigid`]);
    /// `None` for a grounded model.
    pub fn rigid_modes(&self) -> Option<&crate::model::RigidModes> {
        self.rigid.as_deref()
    }

    /// Whether the residual includes the tail correction at the current Ω: the coupling
    /// through the harmonics above H of laws linear in the state whose coefficients jump in
    /// time (see [`HarmonicBasis::with_tail_correction`]).
    pub fn tail_corrected(&self) -> bool {
        self.tail.as_ref().is_some_and(|t| t.applies())
    }

    /// Whether the tail correction would apply at the current Ω with the basis turning it on
    /// (the same as [`HarmonicBalance::tail_corrected`] where it does): a law linear in the
    /// state jumps in time and the harmonics above H are mass-dominated. Builds the
    /// correction once: its FFT plan on 10H–20H samples, a factor of M, the coefficient tables
    /// and a solve with the factors of `Z_H` per jumping element (the 1000-DOF drivetrain:
    /// 0.3–13 ms).
    pub fn tail_correction_would_apply(&self) -> bool {
        self.tail_corrected()
            || tail::TailCorrection::whatever_the_basis(self)
                .ok()
                .flatten()
                .is_some_and(|t| t.applies())
    }

    /// The force harmonics `0..=H` that the tail correction adds to each corrected element,
    /// `(element index in the model, harmonics)`, at the full harmonics `q` (`(H+1)·n` of
    /// the model's DOFs): with them, an element's force balances the equation of motion (see
    /// [`crate::report::element_outputs`]). Empty where the correction does not apply.
    pub fn tail_forces(&self, q: &[Complex64]) -> Vec<(usize, Vec<Complex64>)> {
        let Some(tail) = self.tail.as_deref().filter(|t| t.applies()) else {
            return Vec::new();
        };
        let Some(q) = self.unknowns_of_full(q) else {
            return Vec::new();
        };
        let h = self.basis.harmonics();
        let mut out = Vec::new();
        tail.element_forces(self, &q, &mut tail.buffers(), |active, force| {
            out.push((self.active[active].index, force[..=h].to_vec()));
        });
        out
    }

    /// `true` if every time-varying or nonlinear law is linear in the state
    /// ([`ForceLaw::is_linear_in_state`](crate::force::ForceLaw::is_linear_in_state)): the
    /// Jacobian Newton factors (without the tail correction) is then the same at every `x`,
    /// and Newton factors it once.
    pub fn is_linear_in_state(&self) -> bool {
        self.active.iter().all(|a| {
            let law = self.model.elements()[a.index].law();
            law.is_linear_in_state() && law.memory().is_none()
        })
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
}
