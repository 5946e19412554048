//! `type = "gear_stage"` elements: a [`GearStage`] read from its scene table, every error
//! located at its field (`elements[i].base_radii[1]`).

use crate::model::GearStage;
use crate::Error;
use serde_json::{Map, Value};

/// Reads the fields of one `[[elements]]` table (without `name` and `type`); `at(field)`
/// gives the scene path of a field, `at("")` the element itself.
pub(super) fn read(
    fields: Map<String, Value>,
    name: &str,
    dofs: &super::dofs::Dofs,
    fundamental_order: f64,
    at: impl Fn(&str) -> String,
) -> Result<GearStage, (String, String)> {
    if fields.contains_key("connects") {
        return Err((
            at("connects"),
            "a gear stage names its DOFs with `driving` and `driven`, not `connects`".into(),
        ));
    }
    let stage: GearStage =
        serde_path_to_error::deserialize(Value::Object(fields)).map_err(|x| {
            let path = x.path().to_string();
            let message = x.into_inner().to_string();
            let path = super::field_path(path, &message);
            (if path == "." { at("") } else { at(&path) }, message)
        })?;
    for (field, dof) in [("driving", &stage.driving), ("driven", &stage.driven)] {
        if !dofs.names.iter().any(|d| d == dof) {
            return Err((
                at(field),
                format!("unknown DOF `{dof}` (the scene has: {})", dofs.listing()),
            ));
        }
    }
    let stage = stage.with_fundamental_order(fundamental_order);
    stage
        .validate(&format!("gear stage `{name}`"))
        .map_err(|e| match &e {
            Error::InvalidParameter { name, .. } => (at(name), e.to_string()),
            _ => (at(""), e.to_string()),
        })?;
    Ok(stage)
}
