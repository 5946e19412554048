//! The text summary of `hbal solve`: the solve, the estimate, automatic harmonics, the
//! extremes, the elements and the stability, rendered from the library's
//! [`SolveAnalysis`](hbal::analysis::SolveAnalysis).

use super::element_report;
use hbal::analysis::{SolveAnalysis, StabilityOutcome};
use hbal::scene::Scene;
use hbal::stability::Floquet;

/// Prints the summary; `asked`: stability was asked for.
pub(crate) fn print(scene: &Scene, a: &SolveAnalysis, asked: bool) {
    let sol = &a.solution;
    say!(
        "{}: {} ({}) after {} iteration{}{}, relative residual {:.2e}, solve {:.3} ms",
        scene.file,
        sol.termination,
        if a.switched_to_exact {
            "piecewise_exact"
        } else if a.found_by.is_some() && sol.is_converged() {
            "by a fallback, below"
        } else {
            scene.method.name()
        },
        sol.stats.iterations,
        if sol.stats.iterations == 1 { "" } else { "s" },
        if a.start.is_some() && a.found_by.is_none() {
            " from --start"
        } else {
            ""
        },
        sol.residual(),
        a.seconds.0 * 1e3
    );
    if let Some(how) = &a.found_by {
        say!("  {how}");
    }
    say!(
        "  fundamental {:.6} rad/s, H = {}, N = {}, {}",
        sol.basis().omega(),
        sol.basis().harmonics(),
        sol.basis().samples(),
        match &a.estimate {
            Some(Ok(e)) => format!(
                "error estimate {}{:.1e}, of harmonics 0..{} {:.1e} (against H = {}){}",
                if e.lower_bound { "at least " } else { "" },
                e.relative,
                sol.basis().harmonics(),
                e.kept_harmonics,
                e.reference_harmonics,
                super::quantity_report::summary(&scene.model, e)
            ),
            Some(Err(e)) => format!("no error estimate: {e}"),
            None => "no error estimate (not converged)".to_string(),
        }
    );
    print_auto(a);
    if let Some(x) = &a.extremes {
        say!(
            "  extremes from the closed form in time ({} intervals{}), not from the harmonics 0..{}",
            x.intervals,
            if x.resolved {
                ""
            } else {
                "; APPROXIMATE between them: the work budget allows fewer than 32 per period of the fastest motion"
            },
            sol.basis().harmonics()
        );
    }
    for (i, name) in sol.dof_names().iter().enumerate() {
        say!("  max |q| {name}: {:.6e}", a.max_abs[i]);
    }
    match &a.elements {
        Ok(e) => element_report::lines(e).iter().for_each(|l| say!("  {l}")),
        Err(e) => say!("  element outputs: {e}"),
    }
    print_stability(a, asked);
}

/// The automatic harmonics' levels and the switch to the exact method.
fn print_auto(a: &SolveAnalysis) {
    let Some(record) = &a.auto else {
        return;
    };
    let (auto, levels, capped) = (&record.settings, &record.levels, &record.capped);
    let steps: Vec<String> = levels
        .iter()
        .map(|l| format!("H = {} → {:.1e}", l.harmonics, l.estimate))
        .collect();
    say!(
        "  harmonics: auto, tolerance {:.0e} on {}{}: {}",
        auto.tolerance,
        auto.control.what(),
        if *capped { " (NOT reached)" } else { "" },
        steps.join(", ")
    );
    if let Some(why) = &record.stopped {
        say!(
            "  harmonics: stopped after H = {}: {why}; the last level that succeeded is reported",
            levels.last().map_or(0, |l| l.harmonics)
        );
    }
    if a.switched_to_exact {
        say!(
            "  harmonic balance stopped at the cap H = {} above the tolerance; the scene is linear with piecewise-constant coefficients, so the exact piecewise solution answers instead (the levels after the cap are its own): its harmonics 0..H are exact, its time series and extremes come from its closed form in time",
            auto.max_harmonics
        );
    }
}

/// The stability lines.
fn print_stability(a: &SolveAnalysis, asked: bool) {
    match &a.stability {
        StabilityOutcome::Unavailable(u) => say!("  {u}"),
        StabilityOutcome::NotComputed if asked => {
            say!("  stability: not computed (the solve did not converge)")
        }
        StabilityOutcome::NotComputed => {}
        StabilityOutcome::Computed(f) if a.exact.is_some() => say!(
            "  stability: {}, max |μ| = {} ({} multiplier{} of the exact monodromy matrix{}), {:.1} ms",
            if f.is_stable() { "stable" } else { "unstable" },
            super::modulus(f.max_abs()),
            f.multipliers.len(),
            if f.multipliers.len() == 1 { "" } else { "s" },
            if f.neutral > 0 {
                format!(", {} neutral of the rigid body", f.neutral)
            } else {
                String::new()
            },
            a.seconds.1 * 1e3
        ),
        StabilityOutcome::Computed(f) if f.other_orbit.is_some() => say!(
            "  stability: {}, max |μ| = {} ({} multiplier{}, {} neutral), {:.1} ms; shooting from the HB orbit found another periodic orbit {:.1e} of the dynamic range away (a strongly unstable orbit single shooting cannot hold): the multipliers are the HB orbit's own",
            if f.is_stable() { "stable" } else { "unstable" },
            super::modulus(f.max_abs()),
            f.multipliers.len(),
            if f.multipliers.len() == 1 { "" } else { "s" },
            f.neutral,
            a.seconds.1 * 1e3,
            f.other_orbit.unwrap_or_default(),
        ),
        StabilityOutcome::Computed(f) => say!(
            "  stability: {}, max |μ| = {} ({} multiplier{}, {} neutral), orbit correction {:.1e}{}, {:.1} ms",
            if f.is_stable() { "stable" } else { "unstable" },
            super::modulus(f.max_abs()),
            f.multipliers.len(),
            if f.multipliers.len() == 1 { "" } else { "s" },
            f.neutral,
            f.orbit_correction,
            match (f.polished, f.orbit_distance > hbal::stability::OTHER_ORBIT_DISTANCE) {
                (false, _) if f.reduction.as_ref().is_some_and(|r| r.krylov.is_some()) => {
                    " (multipliers along the HB orbit)".to_string()
                }
                (false, _) => " (shooting did not converge: multipliers along the HB orbit)".to_string(),
                (true, true) => format!(
                    " (the exact orbit starts {:.1e} of the dynamic range from the HB orbit: the HB solution is that far off, or the shooting found a neighbouring orbit of the same kind)",
                    f.orbit_distance
                ),
                (true, false) => String::new(),
            },
            a.seconds.1 * 1e3
        ),
        StabilityOutcome::Failed(e) => say!("  stability: failed: {e}"),
    }
    if let StabilityOutcome::Computed(Floquet {
        reduction: Some(r), ..
    }) = &a.stability
    {
        if let Some(actions) = r.krylov {
            say!(
                "  stability by the Arnoldi iteration on the monodromy action: {actions} actions on all {} DOFs (no 2n × 2n matrix), leading multipliers to about {:.1e} (Krylov and integration parts)",
                r.dofs,
                r.estimate.unwrap_or(f64::NAN)
            );
        }
        let estimate = match (r.estimate, r.comparison_dofs) {
            (Some(e), Some(wider)) => {
                format!(", multipliers to about {e:.1e} (against {wider} coordinates)")
            }
            // Every mode kept: a similarity transform of the full model, nothing to compare.
            (Some(_), None) => {
                ", every mode kept: the model's own multipliers (no reduction)".to_string()
            }
            (None, _) => String::new(),
        };
        if r.krylov.is_none() {
            say!(
                "  stability on a reduced basis: {} coordinates ({} modes below {:.0} rad/s, {} attachment modes){estimate}",
                r.dofs,
                r.modes,
                r.cutoff,
                r.attachment
            );
        }
    }
}
