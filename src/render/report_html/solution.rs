//! The periodic solution at the scene's speed: convergence, error estimate, stability, the
//! time series and spectrum, the DOF and element tables.

use super::{figure, num, percent, result, Inputs};
use crate::analysis::{order_of, SolveAnalysis, StabilityOutcome};
use crate::report::{significant, ElementOutput, HtmlReport};

/// Most rows of the DOF table (the DOFs with the largest max |q| of a larger model).
const MAX_DOF_ROWS: usize = 40;

pub(super) fn solve_section(r: &mut HtmlReport, i: &Inputs) {
    let scene = i.scene;
    r.heading(&format!(
        "Periodic solution at {} {}",
        crate::render::speed_text(scene.basis.omega() / scene.omega_per_speed),
        scene.speed_unit
    ));
    let Some(a) = result(r, i.solved, "solution") else {
        return;
    };
    let sol = &a.solution;
    let iterations = sol.stats.iterations;
    r.status(
        sol.is_converged(),
        &format!(
            "{} ({}) after {iterations} iteration{}",
            sol.termination,
            a.method,
            if iterations == 1 { "" } else { "s" }
        ),
    );
    let basis = sol.basis();
    r.facts(&[
        ("relative residual", num(sol.residual())),
        ("error estimate", estimate_text(a)),
        ("stability", stability_text(&a.stability)),
        (
            "harmonics H, samples N",
            format!("{}, {}", basis.harmonics(), basis.samples()),
        ),
        ("fundamental", format!("{} rad/s", num(basis.omega()))),
        ("solve time", format!("{} ms", num(a.seconds.0 * 1e3))),
    ]);
    let prefix = if sol.is_converged() {
        ""
    } else {
        "not_converged_"
    };
    let dir = i.dir.join("solve");
    figure(r, &dir, &format!("{prefix}time_series.svg"), "One period");
    let spectrum = "Amplitude spectrum over the harmonics";
    figure(r, &dir, &format!("{prefix}spectrum.svg"), spectrum);
    dof_table(r, i, a);
    if let Ok(elements) = &a.elements {
        element_table(r, elements);
    }
}

/// The error estimate in words: the whole, the harmonics 0..H, against which H.
fn estimate_text(a: &SolveAnalysis) -> String {
    match &a.estimate {
        Some(Ok(e)) => format!(
            "{}{}, of harmonics 0..{} {} (against H = {}){}",
            if e.lower_bound { "at least " } else { "" },
            significant(e.relative, 2),
            a.solution.basis().harmonics(),
            significant(e.kept_harmonics, 2),
            e.reference_harmonics,
            match a.auto.as_ref().map(|r| r.settings.control) {
                Some(crate::solve::Control::Harmonics) =>
                    "; automatic harmonics on the harmonics 0..H",
                Some(_) => "; automatic harmonics on the periodic solution",
                None => "",
            }
        ),
        Some(Err(e)) => e.clone(),
        None => "none (not converged)".into(),
    }
}

/// The stability in words.
fn stability_text(s: &StabilityOutcome) -> String {
    match s {
        StabilityOutcome::Unavailable(u) => u.clone(),
        StabilityOutcome::Failed(e) => format!("failed: {e}"),
        StabilityOutcome::NotComputed => "not computed".into(),
        StabilityOutcome::Computed(f) => format!(
            "{}, max |μ| = {} ({} neutral), orbit correction {}",
            if f.is_stable() { "stable" } else { "UNSTABLE" },
            num(f.max_abs()),
            f.neutral,
            num(f.orbit_correction)
        ),
    }
}

/// Every DOF's max |q| and the amplitude of each excitation order.
fn dof_table(r: &mut HtmlReport, i: &Inputs, a: &SolveAnalysis) {
    let orders: Vec<f64> = crate::analysis::excitation_orders(i.scene, &i.scene.basis)
        .into_iter()
        .map(|o| o.0)
        .collect();
    let sol = &a.solution;
    let (n, basis) = (sol.dof_names().len(), sol.basis());
    let order = |k| order_of(k, a.fundamental_order, basis.subharmonic());
    let amplitude = |d: usize, o: f64| {
        (0..=basis.harmonics())
            .find(|&k| (order(k) - o).abs() <= 1e-9 * o.max(1.0))
            .map_or("–".into(), |k| {
                significant(sol.harmonics()[k * n + d].norm(), 4)
            })
    };
    let mut rows: Vec<(f64, Vec<String>)> = (0..n)
        .map(|d| {
            let mut row = vec![sol.dof_names()[d].clone(), num(a.max_abs[d])];
            row.extend(orders.iter().map(|&o| amplitude(d, o)));
            (a.max_abs[d], row)
        })
        .collect();
    r.heading("DOFs");
    if rows.len() > MAX_DOF_ROWS {
        r.paragraph(&format!(
            "The {MAX_DOF_ROWS} of {} DOFs with the largest max |q| (all in solve/harmonics.csv).",
            rows.len()
        ));
        rows.sort_by(|a, b| b.0.total_cmp(&a.0));
        rows.truncate(MAX_DOF_ROWS);
    }
    let titles: Vec<String> = orders.iter().map(|o| format!("order {o}")).collect();
    let mut header = vec!["DOF", "max |q| (rad or m)"];
    header.extend(titles.iter().map(String::as_str));
    let rows: Vec<Vec<String>> = rows.into_iter().map(|r| r.1).collect();
    r.table(&header, &rows);
}

/// Every element's coordinate, force and contact states; the gear stages' transmission
/// error and mesh forces.
fn element_table(r: &mut HtmlReport, elements: &[ElementOutput]) {
    if elements.is_empty() {
        return;
    }
    r.heading("Elements");
    let rows: Vec<Vec<String>> = elements
        .iter()
        .map(|e| {
            let states: Vec<String> = e
                .states
                .iter()
                .map(|(s, f)| format!("{s} {}", percent(*f)))
                .collect();
            vec![
                e.name.clone(),
                e.kind.clone(),
                num(e.coordinate.mean()),
                num(e.coordinate.peak_to_peak()),
                num(e.force.mean()),
                format!("{} … {}", num(e.force.min), num(e.force.max)),
                states.join(", "),
            ]
        })
        .collect();
    let header = [
        "element",
        "type",
        "u mean (m or rad)",
        "u peak to peak",
        "f mean (N or N m)",
        "f min … max",
        "contact states",
    ];
    r.table(&header, &rows);
    let stages: Vec<Vec<String>> = elements
        .iter()
        .filter_map(|e| e.mesh.as_ref().map(|g| (e, g)))
        .map(|(e, g)| {
            let te = g.te_unit;
            vec![
                e.name.clone(),
                format!("{} {te}", num(g.te_mean)),
                format!("{} {te}", num(g.te_peak_to_peak)),
                num(g.force_mean),
                num(g.dynamic_force),
                num(g.dynamic_factor),
            ]
        })
        .collect();
    if !stages.is_empty() {
        let header = [
            "gear stage",
            "TE mean",
            "TE peak to peak",
            "mesh force mean (N)",
            "dynamic mesh force (N)",
            "dynamic factor",
        ];
        r.table(&header, &stages);
    }
}
