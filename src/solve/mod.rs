//! Solvers on the harmonic residual `R(x) = Z x + F_rest(x) - F_ext`, as argmin solvers run
//! by argmin's `Executor`.
//!
//! All are the update `x ← x - a J⁻¹ R(x)` with a different `J`: the dynamic stiffness `Z`
//! ([`FixedPoint`], the paper's iteration, `a = 1 - γ`), the exact AFT Jacobian ([`Newton`]),
//! rank-one updates ([`Broyden`]); [`Anderson`] accelerates the fixed-point map with the
//! history of its last iterates. [`Method`] picks one at run time.

mod accuracy;
mod anderson;
mod auto_start;
mod broyden;
pub mod coarse;
mod fixed_point;
pub mod lu;
mod method;
mod newton;
pub mod piecewise;
mod problem;
mod quadrature;
mod ringing;
mod run;
mod start;
mod time_invariant;
pub use time_invariant::solve_time_invariant;
pub(crate) use time_invariant::{omega_slope, time_invariant_estimate, time_invariant_reference};

pub(crate) use accuracy::refine;
pub use accuracy::{
    auto_first_basis, estimate_error, refined_solution, solve_auto, AutoHarmonics, AutoSolution,
    Control, ErrorEstimate, Level,
};
pub use anderson::{Anderson, AndersonSolver};
pub use broyden::{Broyden, BroydenSolver, InitialJacobian};
pub use fixed_point::{FixedPoint, FixedPointSolver};
pub use method::Method;
pub use newton::{Newton, NewtonSolver};
pub use piecewise::{ExactSolution, PiecewiseExact};
pub use problem::HbProblem;
pub use quadrature::{quadrature_error, QuadratureError, QUADRATURE_OVERSAMPLING};
pub use run::{HbSolver, HbState, Progress, MAX_DENSE_UNKNOWNS};
pub use start::{robust_start, StartReport};

/// The dense-Jacobian guard, for continuation.
pub(crate) fn check_dense_for_continuation(hb: &crate::HarmonicBalance) -> crate::Result<()> {
    run::check_dense("continuation", hb)
}
