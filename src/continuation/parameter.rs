//! A warm-started sweep over any parameter (it does not follow folds).

use super::point::NewPoint;
use super::{Branch, BranchStop, Continuation};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solve::{robust_start, Method, Newton};
use crate::stability::FloquetOptions;
use crate::{Formulation, HarmonicBasis};
use num_complex::Complex64;

/// A warm-started sweep over any parameter: `build(p)` gives the model and basis at `p`; each
/// point starts Newton from the previous one. It stops with [`BranchStop::NotConverged`] where
/// Newton fails (it does not follow folds). Stability as in [`Continuation`]; `formulation`
/// as in [`HarmonicBalance::with_formulation`] (the points always hold every DOF).
pub fn parameter_sweep(
    values: &[f64],
    build: impl FnMut(f64) -> Result<(Model, HarmonicBasis)>,
    stability: Option<FloquetOptions>,
    formulation: Formulation,
    progress: impl FnMut(f64),
) -> Result<Branch> {
    let cont = Continuation {
        stability,
        formulation,
        ..Continuation::default()
    };
    sweep_values(values, build, &cont, progress)
}

/// [`parameter_sweep`] with the settings of `cont` (its method, tolerance, stability,
/// formulation): the method starts the first value, Newton from the previous point the
/// others; with [`Method::PiecewiseExact`] every value is solved exactly (a linear scene's
/// points are independent). A failure after the first value ends the branch with its points.
pub fn sweep_values<M: std::borrow::Borrow<Model>>(
    values: &[f64],
    mut build: impl FnMut(f64) -> Result<(M, HarmonicBasis)>,
    cont: &Continuation,
    mut progress: impl FnMut(f64),
) -> Result<Branch> {
    let mut branch: Option<Branch> = None;
    let mut previous: Option<Vec<Complex64>> = None;
    let formulation = cont.formulation;
    for (i, &p) in values.iter().enumerate() {
        let (model, basis) = match build(p) {
            Ok(v) => v,
            // Keep the points so far.
            Err(e) => {
                end_here(&mut branch, e, |reason| BranchStop::InvalidParameter {
                    parameter: p,
                    reason,
                })?;
                break;
            }
        };
        let model: &Model = model.borrow();
        let failed = |reason| BranchStop::Failed {
            parameter: p,
            reason,
        };
        if matches!(cont.method, Method::PiecewiseExact(_)) {
            // A linear time-invariant model: its exact solution is one solve per harmonic.
            match super::time_invariant::exact_point(model, basis, p) {
                Ok(Some(point)) => {
                    let b = branch.get_or_insert_with(|| {
                        Branch::new(model, basis, super::time_invariant::START.into())
                    });
                    if let Some(reason) = cont.push_point(b, model, point) {
                        b.stop = BranchStop::StabilityFailed {
                            omega: basis.omega(),
                            reason,
                        };
                        break;
                    }
                    progress((i + 1) as f64 / values.len() as f64);
                    if cont.cancel.is_cancelled() && i + 1 < values.len() {
                        b.stop = BranchStop::Cancelled { parameter: p };
                        break;
                    }
                    continue;
                }
                Ok(None) => {}
                Err(e) => {
                    end_here(&mut branch, e, failed)?;
                    break;
                }
            }
        }
        let mut exact = None;
        let sol = if let Method::PiecewiseExact(method) = &cont.method {
            // No harmonic balance to build: every value is solved exactly.
            match method.solve_exact(model, &basis) {
                Ok(e) => {
                    branch
                        .get_or_insert_with(|| Branch::new(model, basis, "piecewise_exact".into()));
                    let sol = e.solution.clone();
                    exact = Some(e);
                    sol
                }
                Err(e) => {
                    end_here(&mut branch, e, failed)?;
                    break;
                }
            }
        } else {
            let mut hb = match HarmonicBalance::with_formulation(model, basis, formulation) {
                Ok(hb) => hb,
                // After the first point, a numerical failure ends the branch and keeps its
                // points.
                Err(e) => {
                    end_here(&mut branch, e, failed)?;
                    break;
                }
            };
            crate::solve::check_dense_for_continuation(&hb)?;
            let mut ws = hb.workspace();
            let full = (basis.harmonics() + 1) * model.n_dofs();
            match &previous {
                Some(q) if q.len() == full => {
                    match Newton::new()
                        .with_tolerance(cont.tolerance)?
                        .solve_from(&hb, q, &mut ws)
                    {
                        // No finite residual from the previous point: Newton fails here.
                        Err(Error::NonFinite { .. }) => {
                            if let Some(b) = branch.as_mut() {
                                b.stop = BranchStop::NotConverged { parameter: p };
                            }
                            break;
                        }
                        r => r?,
                    }
                }
                // The first value: the robust start (other solvers, load homotopy).
                _ => {
                    let start = robust_start(&mut hb, &cont.method, None, cont.tolerance, &mut ws)?;
                    if let Some(b) = branch.as_mut() {
                        b.start = start.how;
                    } else {
                        branch = Some(Branch::new(model, basis, start.how));
                    }
                    start.solution
                }
            }
        };
        let b = branch.get_or_insert_with(|| Branch::new(model, basis, String::new()));
        if !sol.is_converged() {
            b.stop = if i == 0 {
                BranchStop::StartFailed {
                    reason: sol.termination.to_string(),
                }
            } else {
                BranchStop::NotConverged { parameter: p }
            };
            break;
        }
        previous = Some(sol.harmonics().to_vec());
        let point = NewPoint::new(model, basis, sol.harmonics().to_vec(), p, sol.residual()).map(
            |mut point| {
                // The exact solution's own estimate, extremes and multipliers.
                if let Some(e) = exact.take() {
                    point.max_abs = Some(e.extremes().max_abs());
                    point.estimate = Some(e.estimate);
                    point.floquet = Some(e.floquet());
                }
                point
            },
        );
        let failed = match point {
            Ok(point) => cont.push_point(b, model, point),
            Err(reason) => Some(reason),
        };
        if let Some(reason) = failed {
            b.stop = BranchStop::StabilityFailed {
                omega: basis.omega(),
                reason,
            };
            break;
        }
        progress((i + 1) as f64 / values.len() as f64);
        if cont.cancel.is_cancelled() && i + 1 < values.len() {
            b.stop = BranchStop::Cancelled { parameter: p };
            break;
        }
    }
    branch.ok_or_else(|| Error::invalid("parameter sweep", "values", 0.0, "at least one value"))
}

/// Ends `branch` with the stop `stop(reason of e)` if it has points; `e` itself before the
/// first point.
fn end_here(
    branch: &mut Option<Branch>,
    e: crate::error::Error,
    stop: impl FnOnce(String) -> BranchStop,
) -> Result<()> {
    match branch.as_mut() {
        Some(b) => {
            b.stop = stop(e.to_string());
            Ok(())
        }
        None => Err(e),
    }
}
