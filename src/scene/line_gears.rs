//! Rigid gears of a shaft line (`[line] gears`): constraints that remove a DOF.
//!
//! A rigid gear pair between the disks `driving` and `driven` with ratio `i` (driving speed
//! over driven speed, `r_driven / r_driving` from pitch radii) imposes `θ_driven = θ_driving / i`
//! with every angle positive in its own running direction, the sign convention of the elastic
//! `gear_stage` (whose mesh deflection `r1 θ1 − r2 θ2` vanishes here). Each constraint removes
//! one angle: every disk's angle becomes `θ_d = f_d θ_r`, a factor `f_d` times the angle of a
//! kept disk `r` (its root). The line then assembles `M = Tᵀ M_full T` and the same for K and D,
//! `T` the map from the kept angles to all of them, entry by entry: a disk's inertia `J` adds
//! `J f²` at its root, a shaft `k` between disks `a`, `b` adds `k f_a²`, `k f_b²` and `−k f_a f_b`.
//!
//! Which angle goes: the driven disk's, unless another gear removed it already; then the
//! driving disk's root. Two pinions on one bull gear thus keep the first pinion and express the
//! second through it. A chain of gears that closes a loop must agree on its ratios (else an
//! error).

use serde::Deserialize;

/// One rigid gear pair.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RigidGear {
    driving: String,
    driven: String,
    ratio: Option<f64>,
    /// Pitch radii (or tooth counts) `[driving, driven]`: `ratio = driven / driving`.
    radii: Option<[f64; 2]>,
}

/// Per disk: the kept disk its angle follows and the factor, `θ_d = f θ_root`.
pub(super) type Joins = Vec<(usize, f64)>;

/// The joins of `gears` over the disks `names`; errors are `(field path, message)`.
pub(super) fn join(names: &[String], gears: &[RigidGear]) -> Result<Joins, (String, String)> {
    let mut joins: Joins = (0..names.len()).map(|i| (i, 1.0)).collect();
    for (g, gear) in gears.iter().enumerate() {
        let at = |field: &str| format!("line.gears[{g}].{field}");
        let index = |field: &str, name: &str| {
            names.iter().position(|n| n == name).ok_or_else(|| {
                (
                    at(field),
                    format!("unknown disk `{name}` (the line has: {})", names.join(", ")),
                )
            })
        };
        let (a, b) = (
            index("driving", &gear.driving)?,
            index("driven", &gear.driven)?,
        );
        if a == b {
            return Err((
                at("driven"),
                format!("the gear meshes `{}` with itself", gear.driven),
            ));
        }
        let ratio = ratio_of(gear, &at)?;
        // θ_b = θ_a / i with θ_a = fa θ_ra, θ_b = fb θ_rb.
        let ((ra, fa), (rb, fb)) = (joins[a], joins[b]);
        if ra == rb {
            let (want, have) = (fa / ratio, fb);
            if (want - have).abs() > 1e-12 * want.abs().max(have.abs()) {
                return Err((
                    at("ratio"),
                    format!(
                        "closes a loop of gears whose ratios disagree: `{}` turns {} times `{}` through the other gears, and {} times through this one",
                        gear.driven, have / fa, gear.driving, 1.0 / ratio
                    ),
                ));
            }
            continue;
        }
        // Remove the driven disk's root (θ_rb = fa / (i fb) θ_ra), or, where another gear has
        // removed the driven disk already, the driving disk's root (θ_ra = i fb / fa θ_rb).
        let (gone, kept, factor) = if rb == b {
            (rb, ra, fa / (ratio * fb))
        } else {
            (ra, rb, ratio * fb / fa)
        };
        for j in joins.iter_mut().filter(|j| j.0 == gone) {
            *j = (kept, j.1 * factor);
        }
    }
    Ok(joins)
}

/// The gear's ratio: `ratio`, or `radii[1] / radii[0]`; finite and > 0.
fn ratio_of(gear: &RigidGear, at: &dyn Fn(&str) -> String) -> Result<f64, (String, String)> {
    let positive = |field: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err((at(field), format!("must be finite and > 0, got {v}")))
        }
    };
    match (gear.ratio, gear.radii) {
        (Some(r), None) => positive("ratio", r),
        (None, Some([r1, r2])) => Ok(positive("radii", r2)? / positive("radii", r1)?),
        _ => Err((
            at("ratio").trim_end_matches(".ratio").to_string(),
            "give `ratio` (driving speed / driven speed) or `radii = [driving, driven]`, one of them".into(),
        )),
    }
}
