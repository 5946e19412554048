//! Frequency sweeps: a warm-started sweep and pseudo-arclength continuation through turning
//! points, with the stability of every point.
//!
//! Continuation follows the branch `R(x, Ω) = 0` in the scaled unknowns `y = (x/s_x, Ω/s_Ω)`.
//! Predictor: `y_p = y_i + s t_i` along the unit tangent. Corrector: Newton on the bordered
//! system
//!
//! `[[R_x s_x, R_Ω s_Ω], [t_iᵀ]] δ = -[R, t_iᵀ (y - y_p)]`,
//!
//! with the exact AFT Jacobian `R_x` and the analytic `R_Ω`
//! ([`HarmonicBalance::omega_derivative_real_into`](crate::HarmonicBalance::omega_derivative_real_into)).
//! Where the branch runs along Ω and the iterate is within 1e-4 of it, the sweep's corrector
//! keeps Ω and its further steps reuse the factors (chord steps at fixed Ω, while each cuts
//! the residual a hundredfold): a point then costs one new Ω (in the condensed formulation one
//! refactorisation of every `Z_k`) and one Jacobian. The new tangent solves the same matrix
//! with right-hand side `(0, 1)`, which keeps its orientation. A turning point (fold) lies
//! where the Ω-component of the tangent changes sign. The step grows by 1.5 after quick corrector
//! convergence, shrinks by 0.5 after a failure, and the branch stops with a reason (and all
//! points so far) when it falls under its minimum.

mod arclength;
mod auto_harmonics;
mod bordered;
mod cancel;
mod locate;
mod parameter;
mod pipeline;
mod point;
mod speed_homotopy;
mod switch;
mod time_invariant;

pub use cancel::Cancel;
pub use parameter::{parameter_sweep, sweep_values};
pub use point::TurnEvidence;
pub use speed_homotopy::{solve_robustly, solve_with_fallbacks};

use crate::solve::{Method, Newton};
use crate::stability::{Bifurcation, Floquet, FloquetOptions};
use num_complex::Complex64;

/// One periodic solution on a branch.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct BranchPoint {
    /// The swept parameter (Ω itself for a frequency sweep).
    pub parameter: f64,
    /// Fundamental Ω (rad/s).
    pub omega: f64,
    /// Harmonics, harmonic-major (`Q[k * n + i]`).
    pub harmonics: Vec<Complex64>,
    /// `max |q_i|` over one period per DOF.
    pub max_abs: Vec<f64>,
    /// Relative residual.
    pub residual: f64,
    /// Truncation estimate of the point ([`Solution::truncation_estimate`](crate::Solution::truncation_estimate)).
    #[serde(default)]
    pub truncation: f64,
    /// The estimated relative error of the point's periodic solution, against the solution
    /// with 2H harmonics, or more ([`estimate_error`](crate::solve::estimate_error)), if asked for
    /// ([`Continuation::error_estimate`]).
    #[serde(default)]
    pub error_estimate: Option<f64>,
    /// The same for its harmonics `0..=H` alone
    /// ([`ErrorEstimate::kept_harmonics`](crate::solve::ErrorEstimate::kept_harmonics)).
    #[serde(default)]
    pub error_estimate_harmonics: Option<f64>,
    /// The worst DOF or element coordinate by its dynamic part against its own range
    /// ([`ErrorEstimate::worst_quantity`](crate::solve::ErrorEstimate::worst_quantity)).
    #[serde(default)]
    pub worst_quantity: Option<crate::compare::QuantityError>,
    /// The AFT's quadrature error relative to the load where a law's contact crossings take
    /// the corrected trapezoid rule ([`ErrorEstimate::quadrature`](crate::solve::ErrorEstimate::quadrature)).
    #[serde(default)]
    pub quadrature: Option<f64>,
    /// Floquet multipliers, if computed.
    pub floquet: Option<Floquet>,
    /// A turning point of the branch lies between the previous point and this one, confirmed
    /// by the multipliers (a real one crosses +1 between both points), or unconfirmed when
    /// stability is off.
    pub fold: bool,
    /// A turning point of the discretised branch that the multipliers of the exact orbits do
    /// not confirm: a corner of a non-smooth branch or a zig-zag of the discretisation (too
    /// few samples at a contact kink). Not a bifurcation.
    #[serde(default)]
    pub spurious_turn: bool,
    /// For a turn (a fold or a spurious turn): what decided it, the real multipliers above +1
    /// on both sides.
    #[serde(default)]
    pub turn_evidence: Option<TurnEvidence>,
    /// Its Ω, interpolated from the tangents at both points (Ω'(s) linear in arclength).
    pub fold_omega: Option<f64>,
    /// Stability changed between the previous point and this one, with this kind of
    /// critical multiplier.
    pub bifurcation: Option<Bifurcation>,
    /// Where the critical multiplier crosses the unit circle between the previous point and
    /// this one (a branch point, period doubling or Neimark–Sacker point; folds have
    /// [`BranchPoint::fold_omega`]), located on the branch by regula falsi on the exact
    /// orbits' multipliers.
    #[serde(default)]
    pub bifurcation_omega: Option<f64>,
}

impl BranchPoint {
    /// `Some(true)` if stable, `None` if not computed.
    pub fn stable(&self) -> Option<bool> {
        self.floquet.as_ref().map(|f| f.is_stable())
    }
}

/// Why a branch ended.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BranchStop {
    /// The end of the parameter range was reached.
    Reached,
    /// The point limit was reached.
    MaxPoints,
    /// The step fell under its minimum near this Ω.
    StepTooSmall {
        /// Where the branch got stuck.
        omega: f64,
    },
    /// The bordered (or Newton) matrix was singular.
    Singular {
        /// Where.
        omega: f64,
    },
    /// Newton did not converge at this parameter value (a parameter sweep does not follow
    /// folds: use a frequency sweep there).
    NotConverged {
        /// The parameter value.
        parameter: f64,
    },
    /// The scene could not be built at this parameter value (e.g. a negative stiffness).
    InvalidParameter {
        /// The parameter value.
        parameter: f64,
        /// What is wrong.
        reason: String,
    },
    /// The harmonic-balance system could not be set up at this parameter value (an undamped
    /// resonance on a harmonic, a system too large): the points before it are kept.
    Failed {
        /// The parameter value.
        parameter: f64,
        /// Why.
        reason: String,
    },
    /// The stability of a point could not be computed (the point is kept without it).
    StabilityFailed {
        /// Where.
        omega: f64,
        /// Why.
        reason: String,
    },
    /// A switched branch came back onto its parent branch (at its other branch point or
    /// period doubling) near this Ω: a normal end, the parent's points would follow.
    Rejoined {
        /// The first point back on the parent.
        omega: f64,
    },
    /// Branch switching found no new branch at the bifurcation.
    SwitchFailed {
        /// Why.
        reason: String,
    },
    /// The first point did not converge.
    StartFailed {
        /// The solver's termination.
        reason: String,
    },
    /// Automatic harmonics ([`Continuation::run_auto`]): the point at this Ω exceeded the
    /// tolerance (or lay far below it), and the branch goes on from it with `harmonics`
    /// harmonics in the next segment (a normal end of this one).
    HarmonicsChanged {
        /// Where.
        omega: f64,
        /// The next segment's H.
        harmonics: usize,
    },
    /// The caller cancelled the sweep ([`Continuation::cancel`]) after the point at this
    /// parameter value (Ω for a frequency sweep): the points so far are kept.
    Cancelled {
        /// The last point's parameter.
        parameter: f64,
    },
}

impl std::fmt::Display for BranchStop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BranchStop::Reached => write!(f, "end of range reached"),
            BranchStop::MaxPoints => write!(f, "point limit reached"),
            BranchStop::StepTooSmall { omega } => {
                write!(f, "step size under its minimum near Ω = {omega}")
            }
            BranchStop::Singular { omega } => {
                write!(f, "singular bordered system near Ω = {omega}")
            }
            BranchStop::SwitchFailed { reason } => write!(f, "no branch switch: {reason}"),
            BranchStop::HarmonicsChanged { omega, harmonics } => {
                write!(
                    f,
                    "goes on with H = {harmonics} from Ω = {omega} (automatic harmonics)"
                )
            }
            BranchStop::Rejoined { omega } => {
                write!(f, "rejoined the parent branch near Ω = {omega}")
            }
            BranchStop::StabilityFailed { omega, reason } => {
                write!(f, "stability failed near Ω = {omega}: {reason}")
            }
            BranchStop::StartFailed { reason } => {
                write!(f, "first point did not converge: {reason}")
            }
            BranchStop::InvalidParameter { parameter, reason } => {
                write!(f, "invalid scene at parameter {parameter}: {reason}")
            }
            BranchStop::Failed { parameter, reason } => {
                write!(f, "failed at parameter {parameter}: {reason}")
            }
            BranchStop::Cancelled { parameter } => {
                write!(f, "cancelled after the point at {parameter}")
            }
            BranchStop::NotConverged { parameter } => {
                write!(
                    f,
                    "no convergence at parameter {parameter} (a fold in the parameter?)"
                )
            }
        }
    }
}

/// A computed branch.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Branch {
    /// DOF names.
    pub dofs: Vec<String>,
    /// H.
    pub harmonics: usize,
    /// The period multiple ν of the orbits (1; 2 on a period-doubled branch): harmonic k
    /// oscillates at kΩ/ν.
    #[serde(default = "one")]
    pub subharmonic: usize,
    /// Where a secondary branch comes from (`None` for a branch started from a solve).
    #[serde(default)]
    pub origin: Option<Origin>,
    /// The points in branch order.
    pub points: Vec<BranchPoint>,
    /// How the first point was found (see [`robust_start`](crate::solve::robust_start)).
    #[serde(default)]
    pub start: String,
    /// Why it ended.
    pub stop: BranchStop,
    /// What the Floquet analyses of consecutive points share (modes, orbit correction).
    #[serde(skip)]
    pub(crate) stability_cache: crate::stability::FloquetCache,
}

fn one() -> usize {
    1
}

/// Where a secondary branch leaves the branch it was switched from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Origin {
    /// The bifurcation: a branch point or a period doubling.
    pub bifurcation: Bifurcation,
    /// Its Ω, located on the parent branch (to about 1e-9 relative).
    pub omega: f64,
    /// The index of the parent branch's point just after it.
    pub parent_point: usize,
    /// Which side of the parent branch (+1 or -1 along the null vector; 0 when the switch
    /// failed).
    pub side: i8,
    /// `max |q_i|` per DOF of the orbit at the bifurcation (where the branch leaves its
    /// parent).
    #[serde(default)]
    pub max_abs: Vec<f64>,
}

impl BranchStop {
    /// `true` for a normal end: the end of the range, or (a switched branch) back on its
    /// parent.
    pub fn is_normal_end(&self) -> bool {
        matches!(
            self,
            BranchStop::Reached | BranchStop::Rejoined { .. } | BranchStop::HarmonicsChanged { .. }
        )
    }
}

impl Branch {
    /// An empty branch of `model` on `basis` whose first point was found by `start`.
    pub(crate) fn new(model: &crate::Model, basis: crate::HarmonicBasis, start: String) -> Self {
        Self {
            dofs: model.dof_names().to_vec(),
            harmonics: basis.harmonics(),
            subharmonic: basis.subharmonic(),
            origin: None,
            points: Vec::new(),
            start,
            stop: BranchStop::Reached,
            stability_cache: Default::default(),
        }
    }

    /// Number of (confirmed) turning points.
    pub fn folds(&self) -> usize {
        self.points.iter().filter(|p| p.fold).count()
    }

    /// Number of spurious turns (corners, zig-zags) set apart from the folds.
    pub fn spurious_turns(&self) -> usize {
        self.points.iter().filter(|p| p.spurious_turn).count()
    }
}

/// Pseudo-arclength continuation in Ω.
#[derive(Debug, Clone, PartialEq)]
pub struct Continuation {
    /// Solver of the first point (falls back to the others and a load homotopy). Default
    /// Newton with the corrector's tolerance.
    pub method: Method,
    /// Initial step in the scaled unknowns. Default 0.05.
    pub initial_step: f64,
    /// Smallest step before giving up. Default 1e-7.
    pub min_step: f64,
    /// Largest step. Default 1.0.
    pub max_step: f64,
    /// Point limit. Default 2000.
    pub max_points: usize,
    /// Relative residual tolerance of the corrector. Default 1e-10.
    pub tolerance: f64,
    /// Corrector iterations before the step is halved. Default 8.
    pub max_corrector: usize,
    /// How to compute the stability of every point (`None`: no stability). Default: the
    /// default [`FloquetOptions`]. Consecutive points share a
    /// [`FloquetCache`](crate::stability::FloquetCache); the reduction's estimate
    /// ([`FloquetOptions::estimate`]) is computed at the first point and wherever the
    /// stability changes.
    pub stability: Option<FloquetOptions>,
    /// Estimate the error of every point against the solution with 2H harmonics (a Newton
    /// solve there from the point: about the cost of the point's own corrector times 8 with
    /// the dense Jacobian). Default `false`.
    pub error_estimate: bool,
    /// The formulation of the harmonic balance along the branch (the condensed one solves
    /// for the element coordinates; points still carry all DOFs). Default
    /// [`Formulation::Auto`](crate::Formulation::Auto).
    pub formulation: crate::Formulation,
    /// With [`stability`](Self::stability) on and a second core, compute the points'
    /// stability on a worker thread while the next points are traced, if the stability of the
    /// point the branch is followed from took at least this long (`None`: never; the first
    /// point's time includes the modes of a reduced analysis and the reduction's estimate).
    /// The branch is the same as on one thread: the worker appends the points in order, and a
    /// failed stability still ends the branch there; the progress callback runs up to a few
    /// points ahead. Default 200 µs (below, handing points over costs about what it saves:
    /// the Duffing sweep's 50 µs per point were 6 % slower with a worker).
    pub stability_worker: Option<std::time::Duration>,
    /// Checked after every point: once set, the sweep ends with [`BranchStop::Cancelled`].
    /// Default: a token nobody can set.
    pub cancel: Cancel,
}

impl Default for Continuation {
    fn default() -> Self {
        Self {
            method: Method::Newton(Newton::new()),
            initial_step: 0.05,
            min_step: 1e-7,
            max_step: 1.0,
            max_points: 2000,
            tolerance: 1e-10,
            max_corrector: 8,
            stability: Some(FloquetOptions::default()),
            error_estimate: false,
            formulation: crate::Formulation::Auto,
            stability_worker: Some(std::time::Duration::from_micros(200)),
            cancel: Cancel::default(),
        }
    }
}
