//! A first solution that does not give up easily: the chosen solver, then the others, then a
//! homotopy in the load amplitude.
//!
//! From the linear start (or a given orbit) the chosen [`Method`] runs first. If it fails, the
//! other solvers try from the linear start (Newton, Anderson, Broyden, the relaxed fixed point).
//! If all fail, the alternating load is scaled down to `s F_ext` (static load kept), where the
//! response is nearly linear and Newton converges, and raised back to `s = 1` in steps that grow
//! after a success and halve after a failure, each warm-started from the last.

use super::coarse::coarse_harmonics;
use super::{Anderson, Broyden, FixedPoint, Method, Newton};
use crate::error::{Error, Result};
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::Solution;
use num_complex::Complex64;

/// How [`robust_start`] found its solution.
#[derive(Debug, Clone)]
pub struct StartReport {
    /// The solution (converged unless every attempt failed; then the chosen method's result).
    pub solution: Solution,
    /// What worked: `"newton"`, `"anderson (fallback)"`, `"load homotopy (7 steps)"`, or what
    /// failed.
    pub how: String,
}

/// Solves `hb` with `method` (from `initial` if given) and falls back as the module says.
/// `tolerance` is the relative residual every fallback must reach.
pub fn robust_start(
    hb: &mut HarmonicBalance,
    method: &Method,
    initial: Option<&[Complex64]>,
    tolerance: f64,
    ws: &mut Workspace,
) -> Result<StartReport> {
    // A non-finite value at the start of one attempt (a linear start out of range) leaves the
    // others to try: an `Err` is kept until one of them gives a solution.
    let first = attempt(method.solve(hb, initial, ws))?;
    if let Ok(sol) = &first {
        if sol.is_converged() {
            return Ok(StartReport {
                solution: first?,
                how: method.name().to_string(),
            });
        }
    }
    let fallbacks = [
        Method::Newton(Newton::new().with_tolerance(tolerance)?),
        Method::Anderson(Anderson {
            coarse_harmonics: coarse_harmonics(hb.model(), hb.basis()),
            ..Anderson::new().with_tolerance(tolerance)?
        }),
        Method::Broyden(Broyden::new().with_tolerance(tolerance)?),
        Method::FixedPoint(
            FixedPoint::new()
                .with_gamma(0.5)?
                .with_tolerance(tolerance)?
                .with_max_iterations(2000),
        ),
    ];
    for m in &fallbacks {
        if m.name() == method.name() && initial.is_none() {
            continue;
        }
        if let Ok(sol) = attempt(m.solve(hb, None, ws))? {
            if sol.is_converged() {
                return Ok(StartReport {
                    solution: sol,
                    how: format!("{} (fallback)", m.name()),
                });
            }
        }
    }
    let newton = Newton::new().with_tolerance(tolerance)?;
    if let Some(sol) = load_homotopy(hb, &newton, ws)? {
        return Ok(sol);
    }
    let first = first?;
    Ok(StartReport {
        how: format!(
            "{} failed ({}), as did every fallback and the load homotopy",
            method.name(),
            first.termination
        ),
        solution: first,
    })
}

/// Sorts the outcome of one attempt: a solution or a non-finite value go on (`Ok`), any other
/// error ends the start (`Err`).
fn attempt(result: Result<Solution>) -> Result<Result<Solution>> {
    match result {
        Err(e @ Error::NonFinite { .. }) => Ok(Err(e)),
        Err(e) => Err(e),
        Ok(sol) => Ok(Ok(sol)),
    }
}

/// Newton along `s = s0 → 1` with the alternating load scaled by `s`.
fn load_homotopy(
    hb: &mut HarmonicBalance,
    newton: &Newton,
    ws: &mut Workspace,
) -> Result<Option<StartReport>> {
    const MIN_STEP: f64 = 1e-3;
    let mut scale = 1.0;
    let set = |hb: &mut HarmonicBalance, scale: &mut f64, s: f64| {
        hb.scale_alternating_load(s / *scale);
        *scale = s;
    };
    let mut s: f64 = 0.05;
    let mut current: Option<Solution> = None;
    let mut step: f64 = 0.05;
    let mut steps = 0;
    let result = loop {
        set(hb, &mut scale, s);
        let sol = attempt(match &current {
            Some(c) => newton.solve_from(hb, c.harmonics(), ws),
            None => newton.solve(hb, ws),
        })?;
        steps += 1;
        if let Some(sol) = sol.ok().filter(Solution::is_converged) {
            if s >= 1.0 {
                break Some(sol);
            }
            current = Some(sol);
            step = (step * 1.5).min(0.25);
            s = (s + step).min(1.0);
        } else {
            match &current {
                None if s > MIN_STEP => s *= 0.5,
                Some(_) if step > MIN_STEP => {
                    s -= step;
                    step *= 0.5;
                    s += step;
                }
                _ => break None,
            }
        }
        if steps > 200 {
            break None;
        }
    };
    set(hb, &mut scale, 1.0);
    Ok(result.map(|solution| StartReport {
        solution,
        how: format!("load homotopy ({steps} steps)"),
    }))
}
