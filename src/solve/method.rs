//! A solver chosen at run time.

use super::{Anderson, Broyden, FixedPoint, Newton, PiecewiseExact};
use crate::error::Result;
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::Solution;
use num_complex::Complex64;

/// Any of hbal's solvers, with its options; scene files name it in `method`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum Method {
    /// The paper's fixed point with relaxation γ.
    FixedPoint(FixedPoint),
    /// Newton with the exact AFT Jacobian and a line search.
    Newton(Newton),
    /// Good Broyden.
    Broyden(Broyden),
    /// Anderson acceleration of the fixed point.
    Anderson(Anderson),
    /// The exact periodic solution of a linear scene with piecewise-constant coefficients
    /// (no iteration, no truncation; other scenes are refused).
    PiecewiseExact(PiecewiseExact),
}

impl Method {
    /// The method's name.
    pub fn name(&self) -> &'static str {
        match self {
            Method::FixedPoint(_) => "fixed_point",
            Method::Newton(_) => "newton",
            Method::Broyden(_) => "broyden",
            Method::Anderson(_) => "anderson",
            Method::PiecewiseExact(_) => "piecewise_exact",
        }
    }

    /// Solves from zero (`initial = None`) or a warm start.
    pub fn solve(
        &self,
        hb: &HarmonicBalance,
        initial: Option<&[Complex64]>,
        ws: &mut Workspace,
    ) -> Result<Solution> {
        match self {
            Method::FixedPoint(o) => o.solve_from_option(hb, initial, ws),
            Method::Newton(o) => o.solve_from_option(hb, initial, ws),
            Method::Broyden(o) => o.solve_from_option(hb, initial, ws),
            Method::Anderson(o) => o.solve_from_option(hb, initial, ws),
            Method::PiecewiseExact(o) => o.solve_from_option(hb, initial, ws),
        }
    }
}
