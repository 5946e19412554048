//! The last resort for a first point: continuation in the speed from far away.
//!
//! Where every solver and the load homotopy fail (a Duffing oscillator just below its lower
//! fold: the load homotopy meets a fold in the load), the branch is followed by
//! pseudo-arclength continuation from a speed where the response is nearly linear (Ω/2, 2Ω,
//! Ω/4, 4Ω) to Ω, and its last point (which lands exactly on Ω) is the solution.

use super::{BranchStop, Continuation};
use crate::error::Result;
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solution::Solution;
use crate::solve::{robust_start, StartReport};
use crate::HarmonicBasis;
use num_complex::Complex64;

/// Points of one continuation from a far speed at most.
const HOMOTOPY_POINTS: usize = 400;

/// `continuation.method` from `initial` (the linear solution if `None`), and where that does
/// not converge [`solve_robustly`]: the solution and, where the method alone did not find it,
/// the path that did ([`StartReport::how`]). Every path failing: the method's own result
/// with the paths named.
pub fn solve_with_fallbacks(
    model: &Model,
    basis: HarmonicBasis,
    continuation: &Continuation,
    initial: Option<&[Complex64]>,
) -> Result<(Solution, Option<String>)> {
    let hb = HarmonicBalance::with_formulation(model, basis, continuation.formulation)?;
    let mut ws = hb.workspace();
    let own = continuation.method.solve(&hb, initial, &mut ws)?;
    if own.is_converged() {
        return Ok((own, None));
    }
    let robust = solve_robustly(model, basis, continuation)?;
    let from = if initial.is_some() {
        "from the given start"
    } else {
        "from the linear solution"
    };
    let failed = format!(
        "{} failed {from} ({})",
        continuation.method.name(),
        own.termination
    );
    if robust.solution.is_converged() {
        Ok((
            robust.solution,
            Some(format!("{failed}; found by {}", robust.how)),
        ))
    } else {
        Ok((
            own,
            Some(format!(
                "{failed}; so did the other solvers, the load homotopy and the speed homotopy"
            )),
        ))
    }
}

/// [`robust_start`], then continuation in the speed from far away. `continuation` supplies the
/// method, the tolerance and the step limits.
pub fn solve_robustly(
    model: &Model,
    basis: HarmonicBasis,
    continuation: &Continuation,
) -> Result<StartReport> {
    let mut hb = HarmonicBalance::with_formulation(model, basis, continuation.formulation)?;
    let mut ws = hb.workspace();
    let direct = robust_start(
        &mut hb,
        &continuation.method,
        None,
        continuation.tolerance,
        &mut ws,
    )?;
    if direct.solution.is_converged() {
        return Ok(direct);
    }
    let omega = basis.omega();
    // A bounded effort per start speed: a scene that defeats every solver should not run
    // four sweeps of the user's point limit before it is told so.
    let inner = Continuation {
        stability: None,
        error_estimate: false,
        max_points: continuation.max_points.min(HOMOTOPY_POINTS),
        ..continuation.clone()
    };
    let (lo, hi) = model.load_speed_range();
    let mut tried: Vec<f64> = Vec::new();
    for factor in [0.5, 2.0, 0.25, 4.0] {
        // A start outside a table over speed starts at the table's end instead.
        let start = (omega * factor).clamp(lo, hi);
        let factor = start / omega;
        if (factor - 1.0).abs() < 1e-3 || tried.contains(&start) {
            continue;
        }
        tried.push(start);
        let far = HarmonicBasis::new(omega * factor, basis.harmonics())?
            .with_tail_correction_of(&basis)
            .with_samples(basis.samples())?;
        let branch = inner.run_from(model, far, omega, None, |_| {})?;
        if branch.stop != BranchStop::Reached {
            continue;
        }
        let Some(last) = branch.points.last() else {
            continue;
        };
        if last.omega != omega {
            continue;
        }
        // Where the branch turned on the way, other orbits coexist between: which one the
        // solution is depends on the side it came from, and the report says so.
        let turns = branch
            .points
            .windows(3)
            .filter(|w| (w[1].omega - w[0].omega) * (w[2].omega - w[1].omega) < 0.0)
            .count();
        let turned = if turns > 0 {
            format!(
                "; the branch turned {turns} time{} on the way: other orbits may coexist at this speed, this one is reached from {}",
                if turns == 1 { "" } else { "s" },
                if factor < 1.0 { "below" } else { "above" }
            )
        } else {
            String::new()
        };
        return Ok(StartReport {
            solution: Solution::from_harmonics(
                basis,
                model.dof_names().to_vec(),
                last.harmonics.clone(),
                last.residual,
            )?,
            how: format!(
                "speed homotopy from {:.6} rad/s ({} points){turned}",
                omega * factor,
                branch.points.len()
            ),
        });
    }
    Ok(direct)
}
