//! The serde form of a [`SweepAnalysis`]: the JSON document of `hbal sweep --json`, one
//! object with the branch's points (speed, stability, folds, estimates, multipliers, the
//! reported DOFs' harmonics), the secondary branches and where contacts open (field names in
//! docs/json.md).

use super::element_record::order_of;
use super::sweep::SweepAnalysis;
use crate::continuation::{Branch, BranchPoint, BranchStop};
use serde::Serialize;
use serde_json::{json, Value};

/// The version of the JSON documents of the analyses; raised when a field changes meaning or
/// goes away (fields are only added within a version).
pub const SCHEMA_VERSION: u32 = 1;

impl SweepAnalysis {
    /// The JSON record (what [`Serialize`] writes).
    pub fn to_json(&self) -> Value {
        let branch = &self.branch;
        let speed = |w: f64| self.speed(w);
        let fold_speeds: Vec<f64> = branch
            .points
            .iter()
            .filter(|p| p.fold)
            .map(|p| speed(p.fold_omega.unwrap_or(p.omega)))
            .collect();
        json!({
            "schema_version": SCHEMA_VERSION,
            "scene": self.file,
            "unit": self.unit,
            "from": self.from,
            "to": self.to,
            "first_point": branch.start,
            "stop": branch.stop.to_string(),
            "reached": branch.stop == BranchStop::Reached,
            "points": self.points_json(branch),
            "folds": branch.folds(),
            "fold_speeds": fold_speeds,
            "spurious_turns": branch.spurious_turns(),
            "seconds": self.seconds,
            "dofs": branch.dofs,
            "harmonics_dofs": self.reported.iter().map(|&i| &branch.dofs[i]).collect::<Vec<_>>(),
            "branches": self.secondary.iter().map(|b| self.secondary_json(b)).collect::<Vec<_>>(),
            "contact_loss": self.contact_loss,
        })
    }

    /// The points of `branch` as JSON.
    fn points_json(&self, branch: &Branch) -> Vec<Value> {
        let points = branch.points.iter();
        points.map(|p| self.point_json(p, branch)).collect()
    }

    /// One point of `branch` as JSON; harmonic k of a branch with period multiple ν is order
    /// `k · fundamental_order / ν` of the reference shaft (`shaft_order`; `order` is k, or k/ν
    /// on a period-multiplied branch). The harmonics of the reported DOFs only.
    fn point_json(&self, p: &BranchPoint, branch: &Branch) -> Value {
        let speed = |w: f64| self.speed(w);
        let f = p.floquet.as_ref();
        json!({
            "speed": speed(p.omega),
            "omega_rad_s": p.omega,
            "stable": p.stable(),
            "fold": p.fold,
            "fold_speed": if p.fold { p.fold_omega.map(speed) } else { None },
            "spurious_turn": p.spurious_turn,
            "bifurcation": p.bifurcation.map(|b| format!("{b:?}")),
            "bifurcation_speed": p.bifurcation_omega.map(speed),
            "residual": p.residual,
            "truncation": p.truncation,
            "error_estimate": p.error_estimate,
            "error_estimate_harmonics": p.error_estimate_harmonics,
            "worst_quantity": p.worst_quantity,
            "quadrature": p.quadrature,
            "max_abs": p.max_abs,
            "multipliers": f.map(|f| f.pairs()),
            "multipliers_abs": f.map(|f| f.moduli()),
            "neutral": f.map(|f| f.neutral),
            "orbit_correction": f.map(|f| f.orbit_correction),
            "polished": f.map(|f| f.polished),
            "stability_orbit": f.map(|f| f.orbit),
            "orbit_difference": f.and_then(|f| f.orbit_difference),
            "orbit_distance": f.map(|f| f.orbit_distance),
            "other_orbit": f.and_then(|f| f.other_orbit),
            "turn_evidence": p.turn_evidence.map(|e| json!({
                "before_speed": speed(e.before.0), "before_real_above_one": e.before.1,
                "after_speed": speed(e.after.0), "after_real_above_one": e.after.1,
                "turns": e.turns,
            })),
            "harmonics": self.harmonics_json(p, branch),
        })
    }

    /// The reported DOFs' harmonics of point `p` of `branch`, each with its orders.
    fn harmonics_json(&self, p: &BranchPoint, branch: &Branch) -> Vec<Vec<Value>> {
        let n = branch.dofs.len();
        let nu = branch.subharmonic.max(1);
        let harmonic = |i: usize, k: usize| {
            let (c, s) = crate::harmonic::cos_sin(p.harmonics[k * n + i]);
            let shaft_order = order_of(k, self.fundamental_order, nu);
            if nu == 1 {
                json!({"order": k, "harmonic": k, "shaft_order": shaft_order, "cos": c, "sin": s})
            } else {
                json!({"harmonic": k, "order": k as f64 / nu as f64, "shaft_order": shaft_order, "cos": c, "sin": s})
            }
        };
        let reported = self.reported.iter().filter(|&&i| i < n);
        reported
            .map(|&i| (0..=branch.harmonics).map(|k| harmonic(i, k)).collect())
            .collect()
    }

    /// A secondary branch as JSON: where it leaves the main branch, its period multiple, its
    /// points and why it ended.
    fn secondary_json(&self, b: &Branch) -> Value {
        let origin = b.origin.as_ref();
        json!({
            "bifurcation": origin.map(|o| format!("{:?}", o.bifurcation)),
            "from_speed": origin.map(|o| self.speed(o.omega)),
            "from_omega_rad_s": origin.map(|o| o.omega),
            "side": origin.map(|o| o.side),
            "parent_point": origin.map(|o| o.parent_point),
            "period_multiple": b.subharmonic,
            "stop": b.stop.to_string(),
            "reached": b.stop.is_normal_end(),
            "folds": b.folds(),
            "points": self.points_json(b),
        })
    }
}

impl Serialize for SweepAnalysis {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.to_json().serialize(serializer)
    }
}
