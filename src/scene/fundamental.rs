//! The scene's `fundamental` (speed and order) and `engine` tables: Ω, and the order of the
//! fundamental relative to the reference shaft, chosen so that every engine order and every
//! gear-stage mesh order is a harmonic when the scene does not fix it.

type FieldError = (String, String);
use crate::model::engine::common_divisor;
use crate::model::EngineExcitation;
use serde::Deserialize;
use serde_json::{Map, Value};

/// The fundamental frequency: exactly one of `rpm`, `hz`, `rad_s` (the speed of the reference
/// shaft), times `order` (e.g. the mesh order of a shaft speed, so that a scene models only the
/// orders it needs; default 1, or with an `[engine]` table the largest order <= 1 that makes
/// every engine and mesh order a harmonic).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Fundamental {
    rpm: Option<f64>,
    hz: Option<f64>,
    rad_s: Option<f64>,
    order: Option<f64>,
}

/// The fundamental as solved: Ω and how it relates to the scene's speed.
#[derive(Debug, Clone, Copy)]
pub(super) struct Speed {
    /// `rpm`, `hz` or `rad_s`.
    pub(super) unit: &'static str,
    /// The speed as the scene gives it, in `unit`.
    pub(super) speed: f64,
    /// rad/s per unit of speed of the reference shaft.
    pub(super) per_unit: f64,
    /// The order f of the fundamental: Ω = f Ω_ref.
    pub(super) order: f64,
    /// Ω, rad/s.
    pub(super) omega: f64,
    /// `true` if the order was chosen from the engine and mesh orders.
    pub(super) chosen: bool,
    /// `true` if the scene gives `fundamental.order`.
    pub(super) explicit: bool,
}

impl Fundamental {
    /// The stand-in of a scene without an operating point: 1000 rpm.
    pub(super) fn placeholder() -> Self {
        Self {
            rpm: Some(1000.0),
            hz: None,
            rad_s: None,
            order: None,
        }
    }

    /// Ω and the fundamental's order, given the engine table and the raw element tables.
    pub(super) fn speed(
        &self,
        engine: Option<&EngineExcitation>,
        elements: &[Map<String, Value>],
    ) -> Result<Speed, FieldError> {
        let given: Vec<(&str, f64)> = [("rpm", self.rpm), ("hz", self.hz), ("rad_s", self.rad_s)]
            .into_iter()
            .filter_map(|(k, v)| v.map(|v| (k, v)))
            .collect();
        let (unit, per_unit, speed) = match given.as_slice() {
            [("rpm", v)] => ("rpm", std::f64::consts::TAU / 60.0, *v),
            [("hz", v)] => ("hz", std::f64::consts::TAU, *v),
            [(_, v)] => ("rad_s", 1.0, *v),
            _ => {
                return Err((
                    "fundamental".into(),
                    "give exactly one of `rpm`, `hz`, `rad_s`".into(),
                ))
            }
        };
        let order = match (self.order, engine) {
            (Some(o), _) => o,
            (None, None) => 1.0,
            (None, Some(e)) => {
                // A valid table first: the orders below must be finite and positive.
                e.validate("engine").map_err(super::loads::engine_error)?;
                let mesh_orders = elements.iter().filter_map(stage_mesh_order);
                let orders = e.orders.iter().map(|o| o.order);
                common_divisor(orders.chain(mesh_orders).chain([1.0])).ok_or_else(|| {
                    (
                        "fundamental.order".to_string(),
                        "cannot be chosen: the engine and mesh orders have no common divisor \
                         with a denominator up to 1000; give it"
                            .to_string(),
                    )
                })?
            }
        };
        if !(order.is_finite() && order > 0.0) {
            return Err((
                "fundamental.order".into(),
                format!("must be finite and > 0, got {order}"),
            ));
        }
        let omega = speed * per_unit * order;
        if !(omega.is_finite() && omega > 0.0) {
            return Err((
                "fundamental".into(),
                format!("must be finite and > 0, got {omega} rad/s"),
            ));
        }
        Ok(Speed {
            unit,
            speed,
            per_unit,
            order,
            omega,
            chosen: self.order.is_none() && engine.is_some(),
            explicit: self.order.is_some(),
        })
    }
}

/// The mesh order of the speed of a `gear_stage` (`teeth × shaft_order`) or `planetary`
/// (`z_s |sun_order − carrier_order|`) table whose stiffness varies, read leniently (the
/// element's own check reports bad values); `None` for a constant stiffness, which has no
/// mesh order, and for other elements.
pub(super) fn stage_mesh_order(e: &Map<String, Value>) -> Option<f64> {
    let varies = |field: &str| {
        let s = e.get(field);
        let shape = s.and_then(|s| s.get("shape")).and_then(Value::as_str);
        let flat = s.and_then(|s| s.get("amplitude")).and_then(Value::as_f64) == Some(0.0);
        !(shape == Some("constant") || (shape == Some("cosine") && flat))
    };
    let z = match e.get("type").and_then(Value::as_str)? {
        "gear_stage" if varies("stiffness") => {
            let teeth = e.get("teeth")?.as_f64()?;
            teeth * e.get("shaft_order").map_or(Some(1.0), Value::as_f64)?
        }
        "planetary" if varies("sun_stiffness") || varies("ring_stiffness") => {
            let teeth = e.get("teeth")?.as_array()?;
            let (zs, zr) = (teeth.first()?.as_f64()?, teeth.get(1)?.as_f64()?);
            let sun = e.get("sun_order").map_or(Some(1.0), Value::as_f64)?;
            let carrier = match e.get("carrier_order") {
                Some(c) => c.as_f64()?,
                None => sun * zs / (zs + zr),
            };
            zs * (sun - carrier).abs()
        }
        _ => return None,
    };
    (z.is_finite() && z > 0.0).then_some(z)
}
