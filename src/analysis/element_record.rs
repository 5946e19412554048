//! Element outputs of a solve ([`crate::report::element_outputs`], with the exact method's
//! extremes where it answered) and their JSON form; every harmonic is named by its index k
//! (`harmonic`) and by the order it is of the scene's reference speed (`shaft_order`).

use crate::compare::QuantityError;
use crate::report::{ElementOutput, Signal};
use crate::solve::piecewise::ExactExtremes;
use crate::solve::ErrorEstimate;
use crate::{Model, Solution};
use serde_json::{json, Value};

/// The order of harmonic `k` relative to the reference speed: `k · order / ν`.
pub fn order_of(k: usize, fundamental_order: f64, subharmonic: usize) -> f64 {
    k as f64 * fundamental_order / subharmonic.max(1) as f64
}

/// Every element's output, with the exact extremes and mean forces where there are some.
pub(crate) fn element_records(
    model: &Model,
    solution: &Solution,
    extremes: Option<&ExactExtremes>,
) -> Result<Vec<ElementOutput>, String> {
    let outputs = crate::report::element_outputs(model, solution).map_err(|e| e.to_string())?;
    Ok(match extremes {
        Some(x) => outputs
            .into_iter()
            .zip(&x.elements)
            .map(|(o, e)| o.with_exact(e))
            .collect(),
        None => outputs,
    })
}

fn signal_json(s: &Signal, order: impl Fn(usize) -> f64) -> Value {
    json!({
        "mean": s.mean(),
        "min": s.min,
        "max": s.max,
        "peak_to_peak": s.peak_to_peak(),
        "harmonics": s.harmonics.iter().enumerate().map(|(k, x)| {
            let (c, sn) = crate::harmonic::cos_sin(*x);
            json!({"harmonic": k, "shaft_order": order(k), "cos": c, "sin": sn})
        }).collect::<Vec<_>>(),
    })
}

/// The `elements` array of the JSON record.
pub(crate) fn elements_json(
    outputs: &[ElementOutput],
    order: impl Fn(usize) -> f64 + Copy,
) -> Value {
    Value::Array(
        outputs
            .iter()
            .map(|e| {
                json!({
                    "name": e.name,
                    "type": e.kind,
                    "coordinate": signal_json(&e.coordinate, order),
                    "force": signal_json(&e.force, order),
                    "states": e.states.iter().map(|(n, f)| json!({"state": n, "fraction": f})).collect::<Vec<_>>(),
                    "gear_stage": e.mesh,
                })
            })
            .collect(),
    )
}

/// `{"name", "quantity", "error", "range"}` of one quantity named `name`, or null.
fn quantity_json(name: Option<&String>, q: Option<QuantityError>) -> Value {
    match (q, name) {
        (Some(q), Some(name)) => json!({
            "name": name,
            "quantity": q.quantity,
            "error": q.error,
            "range": q.range,
        }),
        _ => Value::Null,
    }
}

/// The `error_estimate` object of the JSON record: the estimate with its worst quantity and
/// worst force (named by `names`) and the contact quadrature's part.
pub(crate) fn estimate_json(e: &ErrorEstimate, names: &(Option<String>, Option<String>)) -> Value {
    json!({
        "relative": e.relative,
        "kept_harmonics": e.kept_harmonics,
        "reference_harmonics": e.reference_harmonics,
        "lower_bound": e.lower_bound,
        "worst_quantity": quantity_json(names.0.as_ref(), e.worst_quantity),
        "worst_force": quantity_json(names.1.as_ref(), e.worst_force),
        "quadrature": e.quadrature.map(|q| json!({
            "relative": q.relative,
            "samples": q.samples,
            "reference_samples": q.reference_samples,
        })),
    })
}
