//! What the exact piecewise solution admits: its size, laws linear with piecewise-constant
//! coefficients, a regular mass matrix, and a free body's balanced, symmetric coupling.

use super::free_body::FreeBody;
use super::PiecewiseExact;
use crate::error::{Error, Result};
use crate::model::Model;

/// Whether [`PiecewiseExact`] can solve `model`: at most [`PiecewiseExact::MAX_DOFS`] DOFs,
/// no law with memory, every law linear time-invariant or piecewise constant
/// ([`ForceLaw::is_piecewise_constant`](crate::force::ForceLaw::is_piecewise_constant)), mean
/// loads that balance on a model that floats free.
pub(super) fn check(model: &Model) -> Result<()> {
    checked(model, None).map(|_| ())
}

/// [`check`], returning the dense matrices it builds and the rigid-body modes.
/// The static balance of a model that floats free is checked at the speed `omega` (without
/// it, where a static load follows the speed, at the solve).
pub(super) fn checked(
    model: &Model,
    omega: Option<f64>,
) -> Result<(crate::model::DenseMatrices, Option<FreeBody>)> {
    let n = model.n_dofs();
    if n > PiecewiseExact::MAX_DOFS {
        return Err(Error::TooLarge {
            what: format!(
                "the exact piecewise solution of {n} DOFs (dense 2n × 2n monodromy matrix)"
            ),
            size: format!("{n} DOFs"),
            limit: format!("{} DOFs", PiecewiseExact::MAX_DOFS),
            advice: "use harmonic balance (newton, anderson) with the condensed formulation".into(),
        });
    }
    if let Some(e) = model.memory_element() {
        return Err(Error::MemoryUnsupported {
            analysis: "the exact piecewise solution (piecewise_exact)".into(),
            element: e.name().into(),
        });
    }
    for e in model.elements() {
        let law = e.law();
        if !(law.is_linear_time_invariant() || law.is_piecewise_constant()) {
            return Err(Error::InvalidElement {
                context: format!("element `{}`", e.name()),
                reason: "method `piecewise_exact` needs every law linear in the state with coefficients constant between jumps in time (linear springs and dampers, constant or rectangular mesh stiffness); use harmonic balance (newton, anderson) for this scene".into(),
            });
        }
    }
    model.refuse_hysteretic("method `piecewise_exact`")?;
    let dense = model.dense("piecewise_exact")?;
    if dense.mass.clone().lu().try_inverse().is_none() {
        return Err(Error::MassNotPositiveDefinite {
            reason: "singular (the exact piecewise solution needs M⁻¹)".into(),
        });
    }
    let free_body = FreeBody::find(model, &dense, omega)?;
    Ok((dense, free_body))
}
