//! The summary `hbal sweep` prints: one line for the branch, then its orbits' notes, the
//! unavailable stability, contact loss, the largest estimates, the folds and stability
//! changes, the turns that are not folds and the switched branches.

use super::speed_text;
use super::sweep_summary::{orbit_hint, orbit_lines, secondary_line};
use hbal::analysis::SweepAnalysis;
use hbal::continuation::BranchStop;
use hbal::scene::Scene;

/// Prints the summary of `a`, a sweep of `scene`; `files` where `--out` writes them.
pub(crate) fn print(scene: &Scene, a: &SweepAnalysis, files: bool) {
    headline(a);
    let speed = |w: f64| a.speed(w);
    let orbits = orbit_lines(&a.branch, &a.unit, speed);
    for line in &orbits {
        say!("  {line}");
    }
    if orbits.is_empty() {
        if let Some(hint) = orbit_hint(&a.branch) {
            say!("  {hint}");
        }
    }
    if let Some(reason) = &a.stability_unavailable {
        say!("  stability unknown: {reason}");
    }
    if let Some(note) = files
        .then(|| super::dof_selection::note(&scene.model, &a.reported))
        .flatten()
    {
        say!("  {note}");
    }
    for c in &a.contact_loss {
        say!(
            "  contact `{}` opens from {} to {} {} (up to {:.1} % of the period)",
            c.element,
            speed_text(c.from),
            speed_text(c.to),
            a.unit,
            100.0 * c.max_open
        );
    }
    estimates(scene, a);
    let failed_start = matches!(a.branch.stop, BranchStop::StartFailed { .. });
    if !a.branch.start.is_empty() && a.branch.start != scene.method.name() && !failed_start {
        say!("  first point: {}", a.branch.start);
    }
    events(a);
    for b in &a.secondary {
        say!("  {}", secondary_line(b, &a.unit, speed));
    }
}

/// The first line: points, range, time, stop, folds, unstable points, spurious turns.
fn headline(a: &SweepAnalysis) {
    let branch = &a.branch;
    let unstable = branch
        .points
        .iter()
        .filter(|p| p.stable() == Some(false))
        .count();
    let spurious = branch.spurious_turns();
    let plural = |n: usize| if n == 1 { "" } else { "s" };
    let turns = if spurious > 0 {
        format!(
            ", {spurious} spurious turn{} (corners or zig-zags the multipliers do not confirm)",
            plural(spurious)
        )
    } else {
        String::new()
    };
    say!(
        "{}: {} points from {} to {} {} in {:.1} ms: {}; {} fold{}, {unstable} unstable point{}{turns}",
        a.file,
        branch.points.len(),
        speed_text(a.from),
        speed_text(a.to),
        a.unit,
        a.seconds * 1e3,
        branch.stop,
        branch.folds(),
        plural(branch.folds()),
        plural(unstable),
    );
}

/// The largest error estimate, the worst quantity and the contact quadrature's error.
fn estimates(scene: &Scene, a: &SweepAnalysis) {
    let (points, unit) = (&a.branch.points, &a.unit);
    let largest = |v: &mut dyn Iterator<Item = (f64, f64)>| v.max_by(|x, y| x.0.total_cmp(&y.0));
    let worst = largest(
        &mut points
            .iter()
            .filter_map(|p| p.error_estimate.map(|e| (e, p.omega))),
    );
    if let Some((e, w)) = worst {
        let kept = points
            .iter()
            .filter_map(|p| p.error_estimate_harmonics)
            .fold(f64::NAN, f64::max);
        let of_kept = if kept.is_nan() {
            String::new()
        } else {
            format!(", of harmonics 0..{} {kept:.1e}", a.branch.harmonics)
        };
        let against = if matches!(scene.method, hbal::solve::Method::PiecewiseExact(_)) {
            "what the exact solution lacks above H, and rounding".to_string()
        } else if scene.model.is_linear_time_invariant() {
            "a linear time-invariant model is exact in H: rounding, by iterative refinement"
                .to_string()
        } else {
            let h = 2 * a.branch.harmonics;
            format!("against 2H = {h}, more where a jumping stiffness rings above it")
        };
        say!(
            "  largest error estimate {e:.1e} (at {:.6} {unit}){of_kept} ({against})",
            a.speed(w)
        );
    }
    let worst_quantity = points
        .iter()
        .filter_map(|p| p.worst_quantity.map(|q| (q, p.omega)))
        .max_by(|x, y| x.0.error.total_cmp(&y.0.error));
    if let Some((q, w)) = worst_quantity {
        say!(
            "  worst quantity {} {:.1e} of its range {:.3e} (at {:.6} {unit}; dynamic part, with what H lacks)",
            q.quantity.name(&scene.model),
            q.error,
            q.range,
            a.speed(w)
        );
    }
    let quadrature = largest(
        &mut points
            .iter()
            .filter_map(|p| p.quadrature.map(|q| (q, p.omega))),
    );
    if let Some((q, w)) = quadrature {
        say!(
            "  contact quadrature up to {q:.1e} of the load (at {:.6} {unit}; a law with kinks that is not affine between them takes the corrected trapezoid rule, measured against 8 times the samples)",
            a.speed(w)
        );
    }
}

/// The folds and stability changes, and the turns that are not folds.
fn events(a: &SweepAnalysis) {
    let unit = &a.unit;
    let speed = |w: f64| a.speed(w);
    for p in a
        .branch
        .points
        .iter()
        .filter(|p| p.fold || p.bifurcation.is_some())
    {
        let at = match (p.fold, p.fold_omega, p.bifurcation_omega) {
            (true, Some(w), _) => format!("{:.7} {unit} (interpolated)", speed(w)),
            (false, _, Some(w)) => format!("{:.7} {unit} (located)", speed(w)),
            _ => format!("{:.6} {unit}", speed(p.omega)),
        };
        let what = match (p.fold, p.bifurcation) {
            (true, Some(b)) => format!("fold at {at}, stability change ({b:?})"),
            (true, None) => format!("fold at {at}"),
            (_, Some(b)) => format!("stability change ({b:?}) at {at}"),
            (false, None) => continue,
        };
        say!("  {what}, max |q| = {:.6e}", p.max_abs[0]);
    }
    let spurious = a.branch.points.iter().filter(|p| p.spurious_turn);
    for (p, e) in spurious.filter_map(|p| p.turn_evidence.map(|e| (p, e))) {
        let text = |w: f64| format!("{} {unit}", speed_text(speed(w)));
        say!(
            "  turn at {} not a fold: {}",
            text(p.fold_omega.unwrap_or(p.omega)),
            e.describe(&text)
        );
    }
}
