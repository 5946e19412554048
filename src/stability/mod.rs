//! Stability of a periodic solution: Floquet multipliers from the monodromy matrix.
//!
//! The variational equation of `M q̈ + D q̇ + K q + Σ w f(θ, w·q, w·q̇) = f(t)` about a periodic
//! solution `q*(t)` is `ż = A(t) z`, `z = (δq, δq̇)`, with
//!
//! `A(t) = [[0, I], [-M⁻¹ (K + Σ w k(t) wᵀ), -M⁻¹ (D + Σ w d(t) wᵀ)]]`,
//! `k(t) = ∂f/∂u`, `d(t) = ∂f/∂u̇` at `(Ω t, w·q*, w·q̇*)`.
//!
//! The monodromy matrix `Φ(T)` solves `Φ̇ = A(t) Φ`, `Φ(0) = I`, over one period; its
//! eigenvalues are the Floquet multipliers. hbal integrates it together with the orbit itself,
//! restarted at every time jump of a law and at every kink crossing, with the saltation matrix
//! where a force jumps ([`Integrator`]):
//!
//! * where every law is affine between its time jumps and kinks (rectangular or constant mesh
//!   stiffness, backlash and stop contacts, linear springs and dampers), `A` is constant on
//!   each piece and the flow is exact: `Φ` is multiplied by `e^{A h}` per piece, the orbit
//!   marched by exact sub-steps with the load as an oscillator (`exponential` module), the
//!   stiffness of contact modes costs nothing;
//! * otherwise by Dormand–Prince 5(4) with error control, the step limited by the fastest time
//!   scale of the model along the orbit (`flow` module).
//!
//! It starts on the harmonic-balance orbit and polishes it by Newton shooting,
//! `x₀ ← x₀ - (Φ - I)⁻¹ (φ_T(x₀) - x₀)`, so the multipliers belong to the exact periodic orbit
//! next to the HB solution, to the integrator's tolerance, whatever H; the size of that
//! correction ([`Floquet::orbit_correction`]) measures the HB solution's own error at `t = 0`.
//! A sweep's points share a [`FloquetCache`] (the modes of a reduced basis, the last orbit
//! corrections, extrapolated to the next shooting's start, and the last `Φ` as the Jacobian
//! of its chord steps). The exponential flow integrates the orbit alone and forms `Φ` only for
//! the orbits that need it, the converged one at least, from the record of its pieces: with
//! two cores on a second thread while the orbit is integrated (the same `Φ` to the last bit).
//!
//! Rigid-body modes give multipliers that are exactly 1 by construction; they are identified
//! from the model ([`Floquet::neutral`]) and left out of [`Floquet::multipliers`] and the
//! stability decision. The solution is stable if every other multiplier lies inside the unit
//! circle (up to [`STABILITY_MARGIN`]). A multiplier leaving through +1 is a fold (or a
//! symmetry-breaking branch point), through −1 a period doubling, a complex pair a
//! Neimark–Sacker bifurcation.
//!
//! **Large models.** The dense `Φ` costs `O(n³)` per step. From
//! [`FloquetMethod::REDUCED_FROM`] DOFs on (or with [`FloquetMethod::Reduced`]) the same
//! shooting runs on the Galerkin projection onto `V` = the undamped modes of `(K0, M)` below
//! `ω_c = cutoff · H Ω/ν` plus the static attachment modes of the element coordinates (sparse Cholesky of `K0 + σM`, shift-invert subspace iteration), with the
//! model's own force laws on `u_e = (Vᵀw_e)·p`; [`Floquet::reduction`] records the basis and
//! an accuracy estimate against the basis with twice the cut-off. With every mode kept the
//! projection is a similarity transform and gives the dense multipliers.
//!
//! ```
//! use hbal::force::CubicSpring;
//! use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
//! // A Duffing oscillator far from resonance: one stable orbit.
//! let model = Model::builder(&["x"])
//!     .mass_diagonal(&[1.0])
//!     .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.02))
//!     .element("spring", &[("x", 1.0)], CubicSpring::new(1.0, 1.0))
//!     .load("x", 1, 0.1, 0.0)
//!     .build()?;
//! let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.5, 7)?)?;
//! let solution = Newton::new().solve(&hb, &mut hb.workspace())?;
//! let floquet = hbal::stability::floquet(&model, &solution)?;
//! assert!(floquet.is_stable());
//! // The product of the multipliers is det Φ = exp(-c T / m) (Liouville):
//! let product: f64 = floquet.multipliers.iter().map(|m| m.norm()).product();
//! // (to the integrator's default tolerance, rtol 1e-8: here 1e-7)
//! assert!((product - (-0.02 * std::f64::consts::TAU / 0.5_f64).exp()).abs() < 1e-6);
//! # Ok::<(), hbal::Error>(())
//! ```

mod affine;
mod arnoldi;
mod chord;
mod cubic;
mod dispatch;
mod dopri;
pub(crate) mod expm;
mod exponential;
mod flow;
mod generator;
mod guide;
mod harmonic_orbit;
mod integration;
mod kept;
mod kernels;
mod kinks;
mod memory_shooting;
pub use memory_shooting::{available as memory_stability_available, MAX_DOFS as MAX_MEMORY_DOFS};
mod modes;
pub(crate) use modes::lowest_modes;
mod neutral;
mod orbit_check;
mod orbit_identity;
pub use orbit_identity::{orbit_distance, OTHER_ORBIT_DISTANCE};
mod krylov_floquet;
mod linear_rate;
pub(crate) use linear_rate::fastest_rate;
mod pieces;
mod pipeline;
mod propagator;
mod record;
mod reduction;
mod scales;
mod shooting;
mod sparse_action;
mod system;
mod time_invariant;
pub(crate) use time_invariant::eigenvalues as state_eigenvalues;

use crate::error::Result;
use crate::model::Model;
use crate::solution::Solution;
use nalgebra::DMatrix;
use num_complex::Complex64;

pub use dispatch::{FloquetCache, FloquetMethod, Reduction};

/// A multiplier counts as outside the unit circle once its modulus exceeds `1 + margin`.
pub const STABILITY_MARGIN: f64 = 1e-6;

/// How a multiplier sits relative to the unit circle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bifurcation {
    /// Real multiplier near +1.
    Fold,
    /// Real multiplier near −1.
    PeriodDoubling,
    /// A real multiplier through +1 where the branch does not turn: a symmetry-breaking
    /// (pitchfork) or transcritical branch point, where another branch crosses. Set by the
    /// continuation, which sees the branch's geometry.
    BranchPoint,
    /// Complex pair on the unit circle.
    NeimarkSacker,
}

/// Floquet multipliers of a periodic solution.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Floquet {
    /// The multipliers that decide stability, largest modulus first (neutral ones excluded).
    pub multipliers: Vec<Complex64>,
    /// Multipliers that are exactly 1 by construction (two per rigid-body mode), left out.
    #[serde(default)]
    pub neutral: usize,
    /// `max_i |x₀,i - x₀*,i| / s_i`: how far the shooting moved the HB state at `t = 0` to reach
    /// the exact periodic orbit, relative to the state scales (`s_q` the largest `|q|`, `s_v`
    /// the same times the fastest frequency). An independent error estimate of the HB orbit.
    /// On a reduced basis ([`Floquet::reduction`]) measured from the HB state's projection
    /// onto the basis, so the part of the state the basis cannot hold does not count.
    #[serde(default)]
    pub orbit_correction: f64,
    /// `true` if Newton shooting converged; otherwise the multipliers are those along the
    /// orbit started from the HB state (still accurate to about the HB error).
    #[serde(default)]
    pub polished: bool,
    /// The state `(q, q̇)` at `t = 0` of the orbit the multipliers belong to (the exact
    /// periodic orbit when [`Floquet::polished`]).
    #[serde(default)]
    pub orbit_start: Vec<f64>,
    /// Integration steps over all periods integrated: accepted, rejected and event re-steps of
    /// the Runge–Kutta flow, or sub-steps and piece ends of the exponential flow.
    #[serde(default)]
    pub steps: usize,
    /// The reduced basis the multipliers were computed on, with its accuracy estimate; `None`
    /// for the dense monodromy matrix in the model's DOFs.
    #[serde(default)]
    pub reduction: Option<Reduction>,
    /// The orbit the multipliers belong to ([`FloquetOptions::orbit`]; the exact orbit where
    /// the HB orbit's pieces do not apply or the stability decision is too close to call).
    #[serde(default)]
    pub orbit: Orbit,
    /// For the HB orbit's multipliers: their [distance](Floquet::distance) to the exact
    /// orbit's on the same coordinates (on a reduced basis, what the basis does to the exact
    /// orbit is in [`Reduction::estimate`]), the larger of the last two measurements of a sweep (at its first point, every
    /// [`ORBIT_CHECK_EVERY`]-th and where the multipliers have moved by 0.2 since the last;
    /// a single analysis measures its own); `None` for the exact orbit.
    #[serde(default)]
    pub orbit_difference: Option<f64>,
    /// How far the start of the orbit the multipliers belong to lies from the HB state at
    /// `t = 0`, in the HB orbit's dynamic terms ([`orbit_distance`]); 0 for the HB orbit's own
    /// multipliers.
    #[serde(default)]
    pub orbit_distance: f64,
    /// `Some(d)` where the shooting found another periodic orbit than the HB solution's: `d`
    /// (more than [`OTHER_ORBIT_DISTANCE`], or four times the HB solution's truncation estimate where that is larger) away, also when started again from the HB state,
    /// and with multipliers of another kind than the HB orbit's own (a strongly unstable
    /// orbit single shooting cannot hold, whose neighbour it glided onto). The multipliers are
    /// then the HB orbit's own ([`Orbit::Harmonic`]): from the exponential flow's pieces where
    /// every law is piecewise affine along it, from the Runge–Kutta flow of the variational
    /// equation along the HB orbit otherwise.
    #[serde(default)]
    pub other_orbit: Option<f64>,
}

/// How often a sweep measures the HB orbit's multipliers against the exact orbit's
/// ([`Orbit::Harmonic`]): at its first analysis and then at every this-many-th.
pub const ORBIT_CHECK_EVERY: usize = 32;

impl Floquet {
    /// Largest modulus.
    pub fn max_abs(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |m| m.norm())
    }

    /// How far the leading multipliers of `self` lie from those of `other`: the largest
    /// distance of a multiplier of either (modulus at least half the largest of both, at
    /// most 8 of each) to the nearest of the other.
    pub fn distance(&self, other: &Floquet) -> f64 {
        shooting::distance(&self.multipliers, &other.multipliers)
    }

    /// `true` if every multiplier lies inside the unit circle: `max |μ| <= 1 +`
    /// [`STABILITY_MARGIN`].
    pub fn is_stable(&self) -> bool {
        self.max_abs() <= 1.0 + STABILITY_MARGIN
    }

    /// Number of real multipliers greater than `1 +` [`STABILITY_MARGIN`] (a fold or branch
    /// point changes it by one); real as in [`Floquet::critical`].
    pub fn real_unstable(&self) -> usize {
        self.multipliers
            .iter()
            .filter(|m| is_real(m) && m.re > 1.0 + STABILITY_MARGIN)
            .count()
    }

    /// The kind of the critical multiplier (the one of largest modulus): a complex pair is a
    /// Neimark–Sacker point, also at a small argument (a pair at 1.054 ± 0.064i leaves the
    /// circle as a pair, not through +1); a real one (or a pair within 1e-6 of the real axis,
    /// rounding of a double root) is a fold by its argument within 0.1 rad of 0, a period
    /// doubling within 0.1 rad of π.
    pub fn critical(&self) -> Option<Bifurcation> {
        let m = *self.multipliers.first()?;
        let angle = m.arg().abs();
        let real = is_real(&m);
        Some(if real && angle < 0.1 {
            Bifurcation::Fold
        } else if real && angle > std::f64::consts::PI - 0.1 {
            Bifurcation::PeriodDoubling
        } else {
            Bifurcation::NeimarkSacker
        })
    }
}

/// A multiplier within 1e-6 of its modulus of the real axis (a double real root splits into
/// a pair that close by rounding).
fn is_real(m: &Complex64) -> bool {
    m.im.abs() <= 1e-6 * m.norm()
}

/// Options of the Floquet analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloquetOptions {
    /// Relative tolerance of the Runge–Kutta integrator, and of the shooting (converged at a
    /// scaled residual of `10 rtol`). Default 1e-8 (multipliers to about 1e-7 or better; the
    /// exponential flow itself is exact up to rounding and the located crossings).
    pub rtol: f64,
    /// Newton shooting iterations (0: the multipliers along the orbit started from the HB
    /// state; a chord step that gains less than a factor 4 is not counted). Default 6.
    pub max_shooting: usize,
    /// Steps per period before giving up. Default 2 000 000.
    pub max_steps: usize,
    /// Dense monodromy matrix in the model's DOFs or on a reduced basis. Default
    /// [`FloquetMethod::Auto`].
    pub method: FloquetMethod,
    /// Cut-off of the reduced basis as a multiple of the highest frequency of the HB solution,
    /// `ω_c = cutoff · H Ω/ν`: every undamped mode below it is kept. `f64::INFINITY` keeps
    /// every mode (dense eigenproblem, up to 4096 DOFs). Default 3.
    pub cutoff: f64,
    /// Estimate the reduction's error by a second analysis on the basis with twice the cut-off
    /// ([`Reduction::estimate`]); costs that analysis. Default `true`.
    pub estimate: bool,
    /// How the flow over a period is integrated. Default [`Integrator::Auto`].
    pub integrator: Integrator,
    /// Which orbit the monodromy matrix follows. Default [`Orbit::Exact`].
    pub orbit: Orbit,
}

/// The orbit whose monodromy matrix gives the multipliers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Orbit {
    /// The exact periodic orbit next to the HB solution, found by shooting: the orbit is
    /// integrated (sub-steps of the fastest motion, every kink crossing located) and
    /// corrected by Newton ([`Floquet::polished`]).
    #[default]
    Exact,
    /// The HB orbit itself, where the exponential flow applies: its kink crossings are the
    /// roots of the harmonics' element coordinates, and `Φ` is the product of the pieces'
    /// exponentials between them; no orbit is integrated, nothing is polished. The
    /// multipliers are those of the linearisation along the HB solution, as in Hill's method,
    /// accurate to about the HB solution's own error: [`Floquet::orbit_difference`] says how
    /// far from the exact orbit's on the same coordinates, as measured ([`Floquet::orbit_correction`]
    /// is 0: no shooting moved the orbit). Other laws, and [`Integrator::RungeKutta`], fall
    /// back on [`Orbit::Exact`].
    Harmonic,
}

/// The integrator of the orbit and its monodromy matrix over a period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Exact exponentials of the piecewise constant linearisation where every law is affine
    /// between its time jumps and kinks (rectangular or constant mesh stiffness, backlash,
    /// linear springs), Dormand–Prince otherwise.
    #[default]
    Auto,
    /// Dormand–Prince 5(4) with error control (`rtol`) for every model.
    RungeKutta,
}

impl Default for FloquetOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            max_shooting: 6,
            max_steps: 2_000_000,
            method: FloquetMethod::Auto,
            cutoff: 3.0,
            estimate: true,
            integrator: Integrator::Auto,
            orbit: Orbit::Exact,
        }
    }
}

/// Floquet multipliers of `solution` (a periodic solution of `model`) with the default
/// [`FloquetOptions`].
pub fn floquet(model: &Model, solution: &Solution) -> Result<Floquet> {
    FloquetOptions::default().compute(model, solution)
}

/// Eigenvalues sorted by modulus, largest first.
pub(crate) fn eigenvalues(a: &DMatrix<f64>) -> Vec<Complex64> {
    let mut m: Vec<Complex64> = a.complex_eigenvalues().iter().copied().collect();
    m.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    m
}
