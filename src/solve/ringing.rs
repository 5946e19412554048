//! Where a law jumps in time (a rectangular mesh stiffness), every jump rings at the natural
//! frequencies of the modes the jumping element moves. Modes above the harmonics of the error
//! estimate's reference leave that ringing out of it: the estimate of a car drivetrain's
//! transmission error at H = 1024 (mesh modes near harmonic 2300 of a crank/37 fundamental)
//! against 2H said 9e-2 where it is 0.44 off. The reference therefore goes on to 4H and 8H
//! while such modes lie above it ([`reference`]); beyond 8H the estimate is marked a lower
//! bound.

use super::accuracy::refine_by;
use crate::error::Result;
use crate::model::Model;
use crate::solution::Solution;
use crate::{Formulation, HarmonicBasis};

/// The most harmonics of the reference, as a multiple of the solution's.
const MAX_FACTOR: usize = 8;

/// The reference solution the error estimate of `solution` compares against: the one with 2H
/// harmonics, or with 4H or 8H where modes the jumping elements move ring above 2H
/// ([`rings_beyond`]); where a finer one does not converge, the last one found.
pub(super) fn reference(
    model: &Model,
    solution: &Solution,
    formulation: Formulation,
) -> Result<Solution> {
    // A linear time-invariant model: exact up to rounding, measured by iterative refinement.
    if let Some(fine) = super::time_invariant_reference(model, solution)? {
        return Ok(fine);
    }
    let mut fine = refine_by(model, solution, formulation, 2)?;
    let mut factor = 2;
    while factor < MAX_FACTOR && rings_beyond(model, fine.basis()) {
        factor *= 2;
        match refine_by(model, solution, formulation, factor) {
            Ok(s) => fine = s,
            Err(_) => break,
        }
    }
    Ok(fine)
}

/// Largest model whose highest natural frequency [`rings_beyond`] computes (a dense
/// symmetric eigenvalue problem per estimate).
const RINGING_CHECK_DOFS: usize = 64;

/// `true` where a law of `model` jumps in time and modes of `(M, K0)` above the harmonics of
/// `fine` carry more than [`RINGING_SHARE`] of a jumping element's compliance
/// `wᵀ K0⁺ w = Σ_j (w·φ_j)²/ω_j²` (elastic modes, `φ_j` M-normalised): every jump rings at
/// those modes, the content the estimate compares against lacks them, and the estimate is a
/// lower bound (a drivetrain whose mesh modes sit at harmonic 2300 of a crank/37 fundamental:
/// the transmission error at H = 1024 estimated 9e-2 off, truly 0.44). A stiff mode the
/// jumping elements do not move does not count. Not checked above [`RINGING_CHECK_DOFS`]
/// DOFs.
pub(super) fn rings_beyond(model: &Model, fine: &HarmonicBasis) -> bool {
    let jumping: Vec<&crate::model::Element> = model
        .elements()
        .iter()
        .filter(|e| !e.law().time_breakpoints().is_empty())
        .collect();
    if jumping.is_empty() || model.n_dofs() > RINGING_CHECK_DOFS {
        return false;
    }
    let Some(modes) = crate::solve::coarse::normal_modes(model) else {
        return false;
    };
    let resolved = fine.harmonics() as f64 * fine.fundamental();
    let top = modes.frequencies.iter().fold(0.0_f64, |m, w| m.max(*w));
    jumping.iter().any(|e| {
        let (mut beyond, mut all) = (0.0, 0.0);
        for (j, &w) in modes.frequencies.iter().enumerate() {
            if w <= 1e-6 * top {
                continue; // a rigid-body mode
            }
            let share = e
                .weights()
                .iter()
                .map(|&(i, wi)| wi * modes.shapes[(i, j)])
                .sum::<f64>()
                .powi(2)
                / (w * w);
            all += share;
            if w > resolved {
                beyond += share;
            }
        }
        all > 0.0 && beyond > RINGING_SHARE * all
    })
}

/// The share of a jumping element's compliance in modes above the resolved harmonics from
/// which the error estimate is a lower bound.
const RINGING_SHARE: f64 = 1e-4;
