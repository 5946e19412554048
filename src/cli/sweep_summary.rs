//! The branch of `hbal sweep` in words: the lines on the orbits the multipliers belong to, a
//! hint for long sweeps of large models, and the summary line of a secondary branch.

use hbal::continuation::Branch;
use hbal::stability::Orbit;

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
