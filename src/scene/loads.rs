//! The scene's loads: `loads` (harmonics of the fundamental per DOF) and the `engine` table
//! (engine orders per cylinder with a firing order, [`EngineExcitation`]).

use super::dofs::Dofs;
use crate::model::{Cylinders, EngineExcitation, ModelBuilder};
use serde::Deserialize;
use std::collections::HashSet;

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LoadSpec {
    dof: String,
    pub(super) order: usize,
    #[serde(default)]
    cos: Option<f64>,
    #[serde(default)]
    sin: Option<f64>,
    /// How the load follows the speed: `{ exponent, rpm }` (a power law scaling `cos`,
    /// `sin`) or `{ rpm = [...], amplitude = [...], phase = [...] }` (a table, without
    /// `cos`, `sin`).
    #[serde(default)]
    speed: Option<crate::model::SpeedLaw>,
}

/// A field path and a message.
fn fail(path: &str, message: String) -> (String, String) {
    (path.to_string(), message)
}

/// An engine-table error located at its field (`engine.orders[1].order`).
pub(super) fn engine_error(e: crate::Error) -> (String, String) {
    match &e {
        crate::Error::InvalidParameter { name, .. } => {
            fail(&format!("engine.{name}"), e.to_string())
        }
        // The path already says `engine`; a field named first in the reason (or a speed law's
        // context, `engine orders[2].speed`) makes it precise.
        crate::Error::InvalidElement { context, reason } => {
            let field = leading_field(reason).filter(|f| !f.contains(' '));
            let within = context
                .strip_prefix("engine ")
                .filter(|c| c.starts_with("orders["));
            let path = match (within, field) {
                (Some(w), Some(f)) => format!("engine.{w}.{f}"),
                (Some(w), None) => format!("engine.{w}"),
                (None, Some(f)) if f.starts_with("orders[") => format!("engine.{f}"),
                _ => "engine".into(),
            };
            fail(&path, reason.clone())
        }
        _ => fail("engine", e.to_string()),
    }
}

/// The field a library message names first, in backticks (`` `rpm` must be ... ``).
fn leading_field(message: &str) -> Option<&str> {
    message.strip_prefix('`').and_then(|m| m.split('`').next())
}

/// A speed law's error at `path` (`loads[2].speed.rpm`), from the field its message names.
fn speed_error(path: &str, e: crate::Error) -> (String, String) {
    let message = match &e {
        crate::Error::InvalidElement { reason, .. } => reason.clone(),
        _ => e.to_string(),
    };
    let field =
        leading_field(&message).filter(|f| ["exponent", "rpm", "amplitude", "phase"].contains(f));
    match field {
        Some(f) => fail(&format!("{path}.{f}"), message),
        None => fail(path, message),
    }
}

/// Adds the loads and the engine's loads (under a fundamental of order `fundamental_order`).
pub(super) fn add(
    mut builder: ModelBuilder,
    loads: &[LoadSpec],
    engine: Option<&EngineExcitation>,
    dofs: &Dofs,
    known: &HashSet<&str>,
    fundamental_order: f64,
) -> Result<ModelBuilder, (String, String)> {
    if let Some(engine) = engine {
        engine.validate("engine").map_err(engine_error)?;
        for (i, dof) in engine.cylinder_dofs().iter().enumerate() {
            if !known.contains(dof.as_str()) {
                let path = match engine.cylinders {
                    Cylinders::Count(_) => "engine.dof".to_string(),
                    Cylinders::Dofs(_) => format!("engine.cylinders[{i}]"),
                };
                let message = format!("unknown DOF `{dof}` (the scene has: {})", dofs.listing());
                return Err((path, message));
            }
        }
        let loads = engine.loads(fundamental_order).map_err(engine_error)?;
        for (dof, k, c, s, law) in loads {
            builder = match law {
                Some(law) => builder.load_over_speed(&dof, k, c, s, law),
                None => builder.load(&dof, k, c, s),
            };
        }
    }
    for (i, l) in loads.iter().enumerate() {
        if !known.contains(l.dof.as_str()) {
            return Err(fail(
                &format!("loads[{i}].dof"),
                format!(
                    "unknown DOF `{}` (the scene has: {})",
                    l.dof,
                    dofs.listing()
                ),
            ));
        }
        let (cos, sin) = (l.cos.unwrap_or(0.0), l.sin.unwrap_or(0.0));
        if l.order == 0 && sin != 0.0 {
            return Err(fail(
                &format!("loads[{i}].sin"),
                format!(
                    "must be 0 on a static load (order 0, where sin(0 Ωt) = 0), got {sin}: give \
                     the static load in `cos`"
                ),
            ));
        }
        builder = match &l.speed {
            None => builder.load(&l.dof, l.order, cos, sin),
            Some(law) => {
                law.validate("speed")
                    .map_err(|e| speed_error(&format!("loads[{i}].speed"), e))?;
                let law = law.clone().on_fundamental_order(fundamental_order);
                if law.is_table() {
                    if let Some(field) = [("cos", l.cos), ("sin", l.sin)]
                        .iter()
                        .find_map(|(f, v)| v.map(|_| *f))
                    {
                        return Err(fail(
                            &format!("loads[{i}].{field}"),
                            "is given by the table `speed` (amplitude and phase over rpm): leave `cos` and `sin` out".into(),
                        ));
                    }
                    builder.load_over_speed(&l.dof, l.order, 1.0, 0.0, law)
                } else {
                    builder.load_over_speed(&l.dof, l.order, cos, sin, law)
                }
            }
        };
    }
    Ok(builder)
}
