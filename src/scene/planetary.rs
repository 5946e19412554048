//! `type = "planetary"` elements: a [`PlanetarySet`] read from its scene table, every error
//! located at its field (`elements[i].base_radii[2]`).

use crate::model::PlanetarySet;
use crate::Error;
use serde_json::{Map, Value};

/// Reads the fields of one `[[elements]]` table (without `name` and `type`); `at(field)`
/// gives the scene path of a field, `at("")` the element itself. The meshes count their
/// cycles against a fundamental (or base) of order `fundamental_order`.
pub(super) fn read(
    fields: Map<String, Value>,
    name: &str,
    dofs: &super::dofs::Dofs,
    fundamental_order: f64,
    at: impl Fn(&str) -> String,
) -> Result<PlanetarySet, (String, String)> {
    if fields.contains_key("connects") {
        return Err((
            at("connects"),
            "a planetary set names its DOFs with `sun`, `ring`, `carrier` and `planets`, not `connects`".into(),
        ));
    }
    let mut set: PlanetarySet =
        serde_path_to_error::deserialize(Value::Object(fields)).map_err(|x| {
            let path = x.path().to_string();
            let message = x.into_inner().to_string();
            let path = super::field_path(path, &message);
            (if path == "." { at("") } else { at(&path) }, message)
        })?;
    let named = [
        ("sun", &set.sun),
        ("ring", &set.ring),
        ("carrier", &set.carrier),
    ]
    .into_iter()
    .map(|(f, d)| (f.to_string(), d.clone()))
    .chain(
        set.planets
            .iter()
            .enumerate()
            .map(|(i, d)| (format!("planets[{i}]"), d.clone())),
    );
    for (field, dof) in named {
        if !dofs.names.contains(&dof) {
            return Err((
                at(&field),
                format!("unknown DOF `{dof}` (the scene has: {})", dofs.listing()),
            ));
        }
    }
    set.fundamental_order = fundamental_order;
    set.validate(&format!("planetary set `{name}`"))
        .map_err(|e| match &e {
            Error::InvalidParameter { name, .. } => (at(name), e.to_string()),
            _ => (at(""), e.to_string()),
        })?;
    Ok(set)
}
