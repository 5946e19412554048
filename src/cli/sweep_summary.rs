//! The branch of `hbal sweep` in words and JSON: one point as JSON (with every harmonic named
//! by its index and its order of the reference shaft), a secondary branch as JSON, and the
//! summary line of a secondary branch.

use super::multipliers_json;
use hbal::continuation::{Branch, BranchPoint};
use hbal::stability::Orbit;
use serde_json::json;

/// One point of a branch as JSON; harmonic k of a branch with period multiple ν is order
/// `k · fundamental_order / ν` of the reference shaft (`shaft_order`; `order` is kept as it
/// was: k, or k/ν on a period-multiplied branch). The harmonics of the DOFs `reported` only
/// (the document's `harmonics_dofs`).
pub(crate) fn point_json(
    p: &BranchPoint,
    branch: &Branch,
    reported: &[usize],
    fundamental_order: f64,
    speed: impl Fn(f64) -> f64,
) -> serde_json::Value {
    let n = branch.dofs.len();
    let nu = branch.subharmonic.max(1);
    let f = p.floquet.as_ref();
    json!({
        "speed": speed(p.omega),
        "omega_rad_s": p.omega,
        "stable": p.stable(),
        "fold": p.fold,
        "fold_speed": if p.fold { p.fold_omega.map(&speed) } else { None },
        "spurious_turn": p.spurious_turn,
        "bifurcation": p.bifurcation.map(|b| format!("{b:?}")),
        "bifurcation_speed": p.bifurcation_omega.map(&speed),
        "residual": p.residual,
        "truncation": p.truncation,
        "error_estimate": p.error_estimate,
        "error_estimate_harmonics": p.error_estimate_harmonics,
        "worst_quantity": p.worst_quantity,
        "quadrature": p.quadrature,
        "max_abs": p.max_abs,
        "multipliers": f.map(multipliers_json),
        "multipliers_abs": f.map(|f| f.multipliers.iter().map(|m| m.norm()).collect::<Vec<_>>()),
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
        "harmonics": reported.iter().filter(|&&i| i < n).map(|&i| (0..=branch.harmonics).map(|k| {
            let (c, s) = hbal::harmonic::cos_sin(p.harmonics[k * n + i]);
            let shaft_order = super::element_report::order_of(k, fundamental_order, nu);
            if nu == 1 {
                json!({"order": k, "harmonic": k, "shaft_order": shaft_order, "cos": c, "sin": s})
            } else {
                json!({"harmonic": k, "order": k as f64 / nu as f64, "shaft_order": shaft_order, "cos": c, "sin": s})
            }
        }).collect::<Vec<_>>()).collect::<Vec<_>>(),
    })
}

/// The summary lines of the orbits the multipliers belong to: where the shooting found another
/// periodic orbit than the point's (the HB orbit's own multipliers instead), and how many points have the HB orbit's multipliers ([`Orbit::Harmonic`]) with
/// the largest difference to the exact orbit's measured on the way. Empty where every point
/// has its exact orbit's.
pub(crate) fn orbit_lines(branch: &Branch, unit: &str, speed: impl Fn(f64) -> f64) -> Vec<String> {
    let mut lines = Vec::new();
    let floquets = || {
        branch
            .points
            .iter()
            .filter_map(|p| p.floquet.as_ref().map(|f| (p, f)))
    };
    let other: Vec<(f64, f64)> = floquets()
        .filter_map(|(p, f)| f.other_orbit.map(|d| (speed(p.omega), d)))
        .collect();
    if !other.is_empty() {
        let (lo, hi) = other
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), o| {
                (a.min(o.0), b.max(o.0))
            });
        let farthest = other.iter().map(|o| o.1).fold(0.0, f64::max);
        lines.push(format!(
            "shooting from the HB orbit found another periodic orbit at {} point{} between {} and {} {unit} (up to {farthest:.1e} of the dynamic range away, with multipliers of another kind: a strongly unstable orbit single shooting cannot hold): their multipliers are the HB orbit's own",
            other.len(),
            if other.len() == 1 { "" } else { "s" },
            super::speed_text(lo),
            super::speed_text(hi),
        ));
    }
    let far: Vec<f64> = floquets()
        .filter(|(_, f)| {
            f.other_orbit.is_none() && f.orbit_distance > hbal::stability::OTHER_ORBIT_DISTANCE
        })
        .map(|(_, f)| f.orbit_distance)
        .collect();
    if !far.is_empty() {
        lines.push(format!(
            "the exact orbit starts up to {:.1e} of the dynamic range from the HB orbit at {} point{} (the HB solution is that far off there, or the shooting found a neighbouring orbit of the same kind; the multipliers are the exact orbit's)",
            far.iter().copied().fold(0.0, f64::max),
            far.len(),
            if far.len() == 1 { "" } else { "s" }
        ));
    }
    let harmonic: Vec<f64> = floquets()
        .filter(|(_, f)| f.orbit == Orbit::Harmonic && f.other_orbit.is_none())
        .map(|(_, f)| f.orbit_difference.unwrap_or(f64::NAN))
        .collect();
    if !harmonic.is_empty() {
        let largest = harmonic.iter().copied().fold(0.0, f64::max);
        lines.push(format!(
            "stability of the HB orbit at {} of {} points (the others the exact orbit's); multipliers within {largest:.1e} of the exact orbit's where measured",
            harmonic.len(),
            branch.points.len()
        ));
    }
    lines
}

/// A hint for a long sweep of a large model (a reduced basis) with the exact orbit's
/// stability: the HB orbit's would cost a fraction.
pub(crate) fn orbit_hint(branch: &Branch) -> Option<String> {
    let reduced = branch
        .points
        .iter()
        .filter_map(|p| p.floquet.as_ref())
        .filter(|f| f.orbit == Orbit::Exact && f.reduction.is_some())
        .count();
    (reduced >= 100).then(|| {
        "note: --stability-orbit harmonic gives each point the HB orbit's multipliers (where every law is piecewise affine: no orbit integrated, checked against the exact orbit's along the way); the 1000-DOF drivetrain's run-up took 5.0 s instead of 8.0 s".to_string()
    })
}

/// A secondary branch as JSON: where it leaves the main branch, its period multiple, its
/// points and why it ended.
pub(crate) fn secondary_json(
    b: &Branch,
    reported: &[usize],
    fundamental_order: f64,
    speed: impl Fn(f64) -> f64 + Copy,
) -> serde_json::Value {
    let origin = b.origin.as_ref();
    json!({
        "bifurcation": origin.map(|o| format!("{:?}", o.bifurcation)),
        "from_speed": origin.map(|o| speed(o.omega)),
        "from_omega_rad_s": origin.map(|o| o.omega),
        "side": origin.map(|o| o.side),
        "parent_point": origin.map(|o| o.parent_point),
        "period_multiple": b.subharmonic,
        "stop": b.stop.to_string(),
        "reached": b.stop.is_normal_end(),
        "folds": b.folds(),
        "points": b.points.iter().map(|p| point_json(p, b, reported, fundamental_order, speed)).collect::<Vec<_>>(),
    })
}

/// One line on a secondary branch: where it leaves, its period, its points and end.
pub(crate) fn secondary_line(b: &Branch, unit: &str, speed: impl Fn(f64) -> f64) -> String {
    let (what, at, side) = match &b.origin {
        Some(o) => (
            match o.bifurcation {
                hbal::stability::Bifurcation::PeriodDoubling => "period-doubled branch",
                _ => "branch",
            },
            format!("{:.7} {unit}", speed(o.omega)),
            match o.side {
                1 => " (side +)",
                -1 => " (side -)",
                _ => "",
            },
        ),
        None => ("branch", String::from("?"), ""),
    };
    let unstable = b
        .points
        .iter()
        .filter(|p| p.stable() == Some(false))
        .count();
    let end = b.points.last().map_or(String::new(), |p| {
        format!(", ends at {:.7} {unit}", speed(p.omega))
    });
    let folds = match b.folds() {
        0 => String::new(),
        1 => ", 1 fold".to_string(),
        f => format!(", {f} folds"),
    };
    format!(
        "{what}{side} from the {} at {at}{}: {} points{end}{folds}, {} unstable: {}",
        match b.origin.as_ref().map(|o| o.bifurcation) {
            Some(hbal::stability::Bifurcation::PeriodDoubling) => "period doubling",
            _ => "branch point",
        },
        if b.subharmonic > 1 {
            format!(", period {}T", b.subharmonic)
        } else {
            String::new()
        },
        b.points.len(),
        unstable,
        b.stop
    )
}
