//! The scene's `[[elements]]`: a force law named by `type` (built-in or a user's, through
//! typetag) on the coordinate `u = Σ w_i q_i` of `connects`, with an optional `offset`; or a
//! `gear_stage`. Every error names the element's field.

use super::dofs::Dofs;
use super::known_types;
use super::paths::{field_path, locate, quoted};
use crate::force::ForceLaw;
use crate::model::ModelBuilder;
use serde_json::{Map, Value};
use std::collections::{BTreeMap, HashSet};

/// A field path and a message.
fn fail(path: &str, message: String) -> (String, String) {
    (path.to_string(), message)
}

/// Adds the elements to `builder`; gear stages count their shaft orders against a fundamental
/// of order `fundamental_order`, or on the torus against their base's order
/// (`stage_order(name)`).
pub(super) fn add(
    mut builder: ModelBuilder,
    elements: Vec<Map<String, Value>>,
    dofs: &Dofs,
    known: &HashSet<&str>,
    fundamental_order: f64,
    stage_order: &dyn Fn(&str) -> Option<f64>,
) -> Result<ModelBuilder, (String, String)> {
    for (i, e) in elements.into_iter().enumerate() {
        let at = |field: &str| format!("elements[{i}].{field}");
        let mut e = e;
        let name = match e.remove("name") {
            Some(Value::String(s)) => s,
            Some(_) => return Err(fail(&at("name"), "must be a string".into())),
            None => format!("element {i}"),
        };
        if e.get("type").and_then(Value::as_str) == Some("gear_stage") {
            e.remove("type");
            let order = stage_order(&name).unwrap_or(fundamental_order);
            let stage = super::gear_stage::read(e, &name, dofs, order, |f| {
                if f.is_empty() {
                    format!("elements[{i}]")
                } else {
                    at(f)
                }
            })?;
            builder = builder.gear_stage(&name, stage);
            continue;
        }
        if e.get("type").and_then(Value::as_str) == Some("planetary") {
            e.remove("type");
            let order = stage_order(&name).unwrap_or(fundamental_order);
            let set = super::planetary::read(e, &name, dofs, order, |f| {
                if f.is_empty() {
                    format!("elements[{i}]")
                } else {
                    at(f)
                }
            })?;
            builder = builder.planetary(&name, set);
            continue;
        }
        let connects: BTreeMap<String, f64> = match e.remove("connects") {
            Some(v) => serde_path_to_error::deserialize(v).map_err(|x| {
                fail(
                    &at("connects"),
                    format!("{} (a table DOF = weight)", x.into_inner()),
                )
            })?,
            None => {
                return Err(fail(
                    &format!("elements[{i}]"),
                    "missing field `connects` (a table DOF = weight)".into(),
                ))
            }
        };
        if connects.values().all(|w| *w == 0.0) {
            return Err(fail(
                &at("connects"),
                "needs a DOF with a nonzero weight (the coordinate is u = Σ w q)".into(),
            ));
        }
        for dof in connects.keys() {
            if !known.contains(dof.as_str()) {
                return Err(fail(
                    &at("connects"),
                    format!("unknown DOF `{dof}` (the scene has: {})", dofs.listing()),
                ));
            }
        }
        // `offset = u0` on any element: the law on `u - u0` (removed before the law's own
        // fields are read; a law's own field may not be called `offset`).
        let offset = match e.remove("offset") {
            Some(v) => match v.as_f64() {
                Some(x) => Some(x),
                None => {
                    return Err(fail(
                        &at("offset"),
                        format!("must be a number (m or rad), got {v}"),
                    ))
                }
            },
            None => None,
        };
        if e.get("type").and_then(|t| t.as_str()) == Some("offset") {
            return Err(fail(
                &at("type"),
                "`offset` is not an element type: give the law's own `type` and the \
                     field `offset = u0` next to it"
                    .into(),
            ));
        }
        if !e.contains_key("type") {
            return Err(fail(
                &format!("elements[{i}]"),
                format!("missing field `type` (one of: {})", known_types()),
            ));
        }
        let type_name = e
            .get("type")
            .and_then(|t| t.as_str())
            .unwrap_or("")
            .to_string();
        let element = Value::Object(e);
        let law: Box<dyn ForceLaw> =
            serde_path_to_error::deserialize(element.clone()).map_err(|x| {
                let p = x.path().to_string();
                let mut message = x.into_inner().to_string();
                // typetag buffers the element, so serde's path stops at it: find the
                // offending key or value inside the element ourselves.
                let inner = if message.starts_with("unknown field") {
                    quoted(&message).and_then(|k| locate(&element, k, false, String::new()))
                } else if message.starts_with("unknown variant") {
                    quoted(&message).and_then(|v| {
                        locate(&element, v, true, String::new())
                            .or_else(|| locate(&element, v, false, String::new()))
                    })
                } else {
                    None
                };
                let path = match inner {
                    Some(p) => at(&p),
                    None => {
                        let p = field_path(p, &message);
                        if p == "." {
                            format!("elements[{i}]")
                        } else {
                            at(&p)
                        }
                    }
                };
                if quoted(&message) == Some(type_name.as_str()) {
                    message = format!("{message}; known element types: {}", known_types());
                }
                fail(&path, message)
            })?;
        // The law's own check, located at its field (the model checks it again).
        law.validate(&format!("element `{name}`")).map_err(|x| {
            let path = match &x {
                crate::Error::InvalidParameter { name, .. } => {
                    locate(&element, name, false, String::new()).map(|p| at(&p))
                }
                _ => None,
            };
            fail(
                &path.unwrap_or_else(|| format!("elements[{i}]")),
                x.to_string(),
            )
        })?;
        let law = match offset {
            Some(u0) => Box::new(crate::force::Offset::boxed(u0, law)),
            None => law,
        };
        let weights: Vec<(&str, f64)> = connects.iter().map(|(d, w)| (d.as_str(), *w)).collect();
        builder = builder.element_boxed(&name, &weights, law);
    }
    Ok(builder)
}
