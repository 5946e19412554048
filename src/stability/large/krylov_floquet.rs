//! The leading Floquet multipliers of an HB orbit without the `2n × 2n` monodromy matrix:
//! the Arnoldi iteration ([`arnoldi`](super::arnoldi)) on the monodromy action of
//! [`sparse_action`](super::sparse_action), for models with many modes in the excitation band
//! ([`FloquetMethod::Arnoldi`](crate::stability::FloquetMethod::Arnoldi)).
//!
//! What the answer is worth has two parts, both reported (`Reduction::estimate`, relative to
//! the largest modulus): the Krylov part, the change of the leading Ritz values between the
//! last two checks, and the integration part, `‖(Φ_{h/2} − Φ_h) y‖` for the leading unit Ritz
//! vector `y`: the action integrated in half the steps against the action the iteration used
//! (`Φ_h y = V_{k+1} H s` from the Arnoldi relation, no further action). The classical
//! Runge–Kutta method's error falls sixteenfold when the step halves, so that difference is
//! the error of the action the iteration used, to within a few percent, as seen by the
//! multiplier that decides stability. The steps are refined until it is below
//! [`INTEGRATION_TOL`].

use super::sparse_action::VariationalAction;
use crate::error::Result;
use crate::model::Model;
use crate::solution::Solution;
use crate::stability::linear_rate::{absolute_row_sums, inverse_diagonal_mass};
use num_complex::Complex64;

/// Most Krylov vectors (monodromy actions) per analysis.
const MAX_VECTORS: usize = 120;

/// Agreement of the leading Ritz values between two checks, relative to the largest.
const RITZ_TOL: f64 = 1e-8;

/// The integration part of the error the steps are refined to, relative to the largest
/// modulus.
const INTEGRATION_TOL: f64 = 1e-6;

/// Most pieces a step of the action's step bound is cut into.
const MAX_SUBDIVISION: usize = 16;

/// The multipliers of largest modulus of the HB orbit `solution` of `model` by the Arnoldi
/// iteration on the monodromy action (module documentation); `None` where the action does not
/// apply (a law with memory, a mass matrix that is not diagonal, a force that jumps at a
/// kink the orbit crosses, a free-free model, whose neutral multipliers 1 the iteration would
/// not set apart).
pub(crate) fn floquet(
    model: &Model,
    solution: &Solution,
) -> Result<Option<crate::stability::Floquet>> {
    let Some(action) = VariationalAction::new(model, solution, 1)? else {
        return Ok(None);
    };
    let k0 = model.k0();
    let factor = super::modes::ShiftedStiffness::new(
        &k0,
        model.mass(),
        crate::model::RigidModes::shift(model),
    )?;
    let solve = |x: &mut [f64]| {
        let mut m = nalgebra::DMatrix::from_column_slice(x.len(), 1, x);
        factor.solve_in_place(&mut m);
        x.copy_from_slice(m.as_slice());
    };
    if crate::model::RigidModes::find(model, solve).is_some() {
        return Ok(None);
    }
    // Steps refined (each cut into `subdivision`) until the integration part of the error
    // meets INTEGRATION_TOL: its h⁴ law says how far at once.
    let (mut subdivision, mut steps) = (1, 0);
    let (ritz, integration) = loop {
        let refined;
        let action = if subdivision == 1 {
            &action
        } else {
            // A finer grid may find a kink crossing the coarse one missed (a grazing contact
            // whose force jumps there): then the action does not apply after all.
            let Some(a) = VariationalAction::new(model, solution, subdivision)? else {
                return Ok(None);
            };
            refined = a;
            &refined
        };
        let Some((ritz, integration)) = leading(model, solution, action, subdivision)? else {
            return Ok(None);
        };
        steps += (ritz.vectors + 4) * action.steps();
        let top = ritz.values.first().map_or(0.0, |v| v.norm());
        let ratio = integration / (INTEGRATION_TOL * top.max(f64::MIN_POSITIVE));
        if ratio <= 1.0 || subdivision >= MAX_SUBDIVISION {
            break (ritz, integration);
        }
        subdivision = (subdivision as f64 * 1.2 * ratio.powf(0.25))
            .ceil()
            .min(MAX_SUBDIVISION as f64) as usize;
    };
    let top = ritz.values.first().map_or(0.0, |v| v.norm());
    let multipliers: Vec<Complex64> = ritz
        .values
        .iter()
        .copied()
        .filter(|v| v.norm() >= 1e-3 * top)
        .take(2 * super::arnoldi::LEADING)
        .collect();
    Ok(Some(crate::stability::Floquet {
        multipliers,
        neutral: 0,
        orbit_correction: 0.0,
        polished: false,
        orbit_start: crate::stability::hb_state::hb_start(solution),
        steps,
        reduction: Some(crate::stability::Reduction {
            dofs: model.n_dofs(),
            modes: 0,
            attachment: 0,
            cutoff: f64::INFINITY,
            estimate: Some(ritz.change.max(integration) / top.max(f64::MIN_POSITIVE)),
            comparison_dofs: None,
            krylov: Some(ritz.vectors),
        }),
        orbit: crate::stability::Orbit::Harmonic,
        orbit_difference: None,
        orbit_distance: 0.0,
        other_orbit: None,
    }))
}

/// The Arnoldi iteration on `action` (its steps cut into `subdivision`) and the integration
/// part of its error; `None` where the finer action does not apply.
fn leading(
    model: &Model,
    solution: &Solution,
    action: &VariationalAction,
    subdivision: usize,
) -> Result<Option<(super::arnoldi::Ritz, f64)>> {
    let dim = action.dim();
    // A deterministic start with every component present.
    let start: Vec<f64> = (0..dim)
        .map(|i| 1.0 + 0.5 * (((i * 7919) % 997) as f64 / 997.0 - 0.5))
        .collect();
    let ritz = super::arnoldi::leading_eigenvalues(
        dim,
        |x, out| action.apply(x, out),
        &start,
        MAX_VECTORS,
        RITZ_TOL,
    )?;
    let integration = if ritz.values.is_empty() {
        Some(0.0)
    } else {
        integration_error(model, solution, &ritz, subdivision)?
    };
    Ok(integration.map(|e| (ritz, e)))
}

/// `‖(Φ_{h/2} − Φ_h) y‖` for the leading unit Ritz vector `y` (module documentation), `Φ_h y`
/// from the Arnoldi relation; the two fine actions (real and imaginary part) side by side.
fn integration_error(
    model: &Model,
    solution: &Solution,
    ritz: &super::arnoldi::Ritz,
    subdivision: usize,
) -> Result<Option<f64>> {
    let Some(fine) = VariationalAction::new(model, solution, 2 * subdivision)? else {
        return Ok(None);
    };
    let (re, im) = &ritz.leading_vector;
    let threads = crate::linear::parallel::threads_for_long_tasks().min(2);
    let images = crate::linear::parallel::map_owned(vec![re, im], threads, |_, x| {
        let mut out = vec![0.0; x.len()];
        fine.apply(x, &mut out).map(|_| out)
    });
    let coarse = [&ritz.leading_image.0, &ritz.leading_image.1];
    let mut squared = 0.0;
    for (fine, coarse) in images.into_iter().zip(coarse) {
        squared += fine?
            .iter()
            .zip(coarse)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>();
    }
    Ok(Some(squared.sqrt()))
}

/// Smallest model whose multipliers [`FloquetMethod::Auto`](crate::stability::FloquetMethod::Auto) takes
/// from the Arnoldi iteration when every mode lies below the reduction's cut-off (a reduced
/// basis would keep them all: a dense `2n × 2n` monodromy matrix).
pub const ARNOLDI_FROM: usize = 256;

/// `true` if every natural frequency of `(K0, M)` lies below `cutoff` (rad/s) by Gershgorin's
/// bound `ω² ≤ max_i Σ_j |K0_ij| / M_ii` (a diagonal mass matrix; `false` otherwise).
pub(crate) fn every_mode_below(model: &Model, cutoff: f64) -> bool {
    let Some(inv_mass) = inverse_diagonal_mass(model) else {
        return false;
    };
    let bound = absolute_row_sums(&model.k0())
        .iter()
        .zip(&inv_mass)
        .map(|(r, m)| r * m)
        .fold(0.0, f64::max);
    bound <= cutoff * cutoff
}
