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
    cos: f64,
    #[serde(default)]
    sin: f64,
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
        // The path already says `engine`.
        crate::Error::InvalidElement { reason, .. } => fail("engine", reason.clone()),
        _ => fail("engine", e.to_string()),
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
        for (dof, k, c, s) in loads {
            builder = builder.load(&dof, k, c, s);
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
        if l.order == 0 && l.sin != 0.0 {
            return Err(fail(
                &format!("loads[{i}].sin"),
                format!(
                    "must be 0 on a static load (order 0, where sin(0 Ωt) = 0), got {}: give \
                     the static load in `cos`",
                    l.sin
                ),
            ));
        }
        builder = builder.load(&l.dof, l.order, l.cos, l.sin);
    }
    Ok(builder)
}
