//! The first level of automatic harmonics, found without giving up: the chosen method, then the
//! other solvers, the load homotopy and continuation in the speed
//! ([`solve_with_fallbacks`](crate::continuation::solve_with_fallbacks)); where every path fails
//! at one H, the same at 2H (a level whose harmonics cannot hold the orbit may have no
//! solution at all), up to the cap.

use super::accuracy::scaled;
use super::{AutoHarmonics, Method};
use crate::continuation::{solve_with_fallbacks, Continuation};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solution::Solution;
use crate::HarmonicBasis;

/// The first converged level from `basis` on, and the path that found it where the method
/// alone did not (with the levels that failed before it).
pub(super) fn first_level(
    model: &Model,
    mut basis: HarmonicBasis,
    method: &Method,
    auto: &AutoHarmonics,
) -> Result<(Solution, Option<String>)> {
    let continuation = Continuation {
        method: *method,
        formulation: auto.formulation,
        tolerance: 1e-10,
        ..Continuation::default()
    };
    let mut failed: Vec<String> = Vec::new();
    loop {
        let (solution, how) = solve_with_fallbacks(model, basis, &continuation, None)?;
        let h = basis.harmonics();
        if solution.is_converged() {
            let how = match (how, failed.is_empty()) {
                (how, true) => how,
                (how, false) => Some(format!(
                    "{}; {}",
                    failed.join("; "),
                    how.unwrap_or_else(|| format!("{} converged at H = {h}", method.name()))
                )),
            };
            return Ok((solution, how));
        }
        failed.push(format!(
            "no converged solution at H = {h} ({})",
            how.unwrap_or_else(|| solution.termination.to_string())
        ));
        let next = 2 * h.max(1);
        if next > auto.max_harmonics {
            return Err(Error::Solver {
                reason: format!("automatic harmonics: {}", failed.join("; ")),
            });
        }
        basis = scaled(&basis, next)?;
    }
}
