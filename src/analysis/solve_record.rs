//! The serde form of a [`SolveAnalysis`]: the JSON document of `hbal solve --json`, one
//! object with the solve, the estimate, automatic harmonics, the stability, every DOF's
//! harmonics and extremes and the element outputs (field names in docs/json.md).

use super::element_record::{elements_json, estimate_json, order_of};
use super::solve::{SolveAnalysis, StabilityOutcome};
use serde::Serialize;
use serde_json::{json, Value};

impl SolveAnalysis {
    /// The JSON record (what [`Serialize`] writes).
    pub fn to_json(&self) -> Value {
        let sol = &self.solution;
        let basis = sol.basis();
        let order = |k| order_of(k, self.fundamental_order, basis.subharmonic());
        json!({
            "schema_version": super::SCHEMA_VERSION,
            "converged": sol.is_converged(),
            "termination": sol.termination.to_string(),
            "method": self.method,
            "switched_to_exact": self.switched_to_exact,
            "found_by": self.found_by,
            "iterations": sol.stats.iterations,
            "residual": sol.residual(),
            "truncation_estimate": sol.truncation_estimate(),
            "error_estimate": match &self.estimate {
                None => Value::Null,
                Some(Ok(e)) => estimate_json(e, &self.quantity_names),
                Some(Err(e)) => json!({"error": e}),
            },
            "auto_harmonics": self.auto.as_ref().map(|a| json!({
                "tolerance": a.settings.tolerance,
                "max": a.settings.max_harmonics,
                "control": a.settings.control,
                "reached": !a.capped,
                "stopped": a.stopped,
                "levels": a.levels,
            })),
            // Where max_abs and the elements' extremes come from.
            "extremes_from": match &self.extremes {
                Some(x) => json!({"closed_form": {"intervals": x.intervals, "resolved": x.resolved}}),
                None => json!("harmonics"),
            },
            "fundamental_rad_s": basis.omega(),
            "harmonics": basis.harmonics(),
            "samples": basis.samples(),
            "solve_seconds": self.seconds.0,
            "start": self.start,
            "stability": self.stability_json(),
            "dofs": self.dofs_json(),
            "elements": match &self.elements {
                Ok(e) => elements_json(e, order),
                Err(e) => json!({ "error": e }),
            },
            "history": sol.history,
        })
    }

    fn stability_json(&self) -> Value {
        match &self.stability {
            StabilityOutcome::NotComputed => Value::Null,
            StabilityOutcome::Unavailable(u) => json!({ "unavailable": u }),
            StabilityOutcome::Failed(e) => json!({ "error": e }),
            StabilityOutcome::Computed(f) => json!({
                "stable": f.is_stable(),
                "orbit": f.orbit,
                "orbit_distance": f.orbit_distance,
                "other_orbit": f.other_orbit,
                "max_abs": f.max_abs(),
                "multipliers": f.pairs(),
                "moduli": f.moduli(),
                "neutral": f.neutral,
                "orbit_correction": f.orbit_correction,
                "polished": f.polished,
                "seconds": self.seconds.1,
                "reduction": f.reduction,
            }),
        }
    }

    fn dofs_json(&self) -> Value {
        let sol = &self.solution;
        let basis = sol.basis();
        let order = |k| order_of(k, self.fundamental_order, basis.subharmonic());
        sol.dof_names()
            .iter()
            .enumerate()
            .map(|(i, name)| {
                json!({
                    "name": name,
                    "max_abs": self.max_abs[i],
                    "harmonics": (0..=basis.harmonics()).map(|k| {
                        let (c, s) = sol.cos_sin(i, k);
                        // `order` is the harmonic index, kept for `--start` files.
                        json!({"order": k, "harmonic": k, "shaft_order": order(k), "cos": c, "sin": s})
                    }).collect::<Vec<_>>(),
                })
            })
            .collect()
    }
}

impl Serialize for SolveAnalysis {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.to_json().serialize(serializer)
    }
}
