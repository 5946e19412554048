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
    let inner = Continuation {
        stability: None,
        error_estimate: false,
        ..*continuation
    };
    for factor in [0.5, 2.0, 0.25, 4.0] {
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
        return Ok(StartReport {
            solution: Solution::from_harmonics(
                basis,
                model.dof_names().to_vec(),
                last.harmonics.clone(),
                last.residual,
            )?,
            how: format!(
                "speed homotopy from {:.6} rad/s ({} points)",
                omega * factor,
                branch.points.len()
            ),
        });
    }
    Ok(direct)
}
