//! `hbal report` of a scene on several base frequencies: one self-contained `report.html` with
//! the bases and their truncation estimates, every element's transmission-error and force lines
//! labelled by their combination, the DOFs, the spectrum, and with `--to` the run-up's order
//! cuts, waterfall (sidebands included) and the points that did not converge. The parts' files
//! go to `DIR/solve` and `DIR/sweep` as `hbal solve` and `hbal sweep` write them.

use super::report::{cancelled, options, Report, ReportParts, ReportSettings};
use super::{prepare_out, speed_text};
use crate::analysis::{Observer, Spectrum, TorusSolveAnalysis, TorusSolveSettings};
use crate::analysis::{TorusSweepAnalysis, TorusSweepSettings};
use crate::error::Result;
use crate::report::HtmlReport;
use crate::scene::Scene;
use std::path::Path;

/// Points of the report's run-up by default.
const RUN_UP_POINTS: usize = 101;

/// Lines per element in the report's tables.
const TABLE_LINES: usize = 8;

/// The report of a torus scene ([`super::report`]).
pub(super) fn report(
    scene: &Scene,
    scene_text: &str,
    settings: &ReportSettings,
    dir: &Path,
    observer: &mut dyn Observer,
) -> Result<Report> {
    for (flag, given) in [
        ("--max-step", settings.max_step.is_some()),
        ("--max-points", settings.max_points.is_some()),
    ] {
        if given {
            return Err(options(
                flag,
                "is a continuation's: a run-up on several base frequencies takes evenly spaced --points",
            ));
        }
    }
    let sweep = settings.to.map(|to| TorusSweepSettings {
        from: settings.from,
        to,
        points: settings.points.unwrap_or(RUN_UP_POINTS),
    });
    let shown = match &sweep {
        Some(sweep) => {
            crate::analysis::check_torus_sweep(scene, sweep)?;
            super::torus_shown(scene, settings.output.as_deref())?
        }
        None => None,
    };
    prepare_out(dir, &["report.html".to_string()])?;
    prepare_out(&dir.join("solve"), &super::torus_solve_files())?;
    if settings.to.is_some() {
        prepare_out(&dir.join("sweep"), &super::torus_sweep_files())?;
    }
    let mut warnings = Vec::new();
    observer.stage(&format!(
        "solving {} at its speed on several base frequencies",
        scene.file
    ));
    let solved = crate::analysis::torus_solve(scene, &TorusSolveSettings::default())?;
    super::write_torus_solve_files(&dir.join("solve"), scene, &solved, &mut warnings)?;
    let swept = match &sweep {
        None => None,
        Some(sweep) => {
            observer.stage(&format!(
                "run-up to {} {}",
                speed_text(sweep.to),
                scene.speed_unit
            ));
            cancelled(settings)?;
            let a = crate::analysis::torus_sweep(scene, sweep, observer)?;
            let out = dir.join("sweep");
            super::write_torus_sweep_files(&out, scene, &a, shown.as_deref(), &mut warnings)?;
            Some(a)
        }
    };
    cancelled(settings)?;
    let page = page(scene, scene_text, dir, &solved, swept.as_ref());
    let file = dir.join("report.html");
    std::fs::write(&file, page).map_err(|e| super::cannot_write(dir, e))?;
    let exit_code = solved
        .exit_code()
        .max(swept.as_ref().map_or(0, |a| a.exit_code()));
    Ok(Report {
        file,
        parts: ReportParts::Torus {
            solved: Box::new(solved),
            swept: swept.map(Box::new),
        },
        warnings,
        exit_code,
    })
}

/// The page.
fn page(
    scene: &Scene,
    scene_text: &str,
    dir: &Path,
    solved: &TorusSolveAnalysis,
    swept: Option<&TorusSweepAnalysis>,
) -> String {
    let mut page = HtmlReport::new(&format!("hbal report: {}", scene.file));
    overview(&mut page, scene, scene_text, solved);
    for (coordinate, force) in solved.elements.iter().zip(&solved.forces) {
        page.heading(&format!("Element {}", coordinate.name));
        lines_table(
            &mut page,
            "coordinate (a gear stage: transmission error, m)",
            coordinate,
        );
        lines_table(&mut page, "force (a gear stage: mesh force, N)", force);
    }
    page.heading("DOFs");
    let rows: Vec<Vec<String>> = solved
        .dofs
        .iter()
        .map(|s| {
            let top = s.lines.first();
            vec![
                s.name.clone(),
                format!("{:.4e}", s.mean),
                format!("{:.4e}", s.rms),
                top.map_or(String::new(), |l| l.label.clone()),
                top.map_or(String::new(), |l| format!("{:.4e}", l.amplitude)),
            ]
        })
        .collect();
    page.table(
        &[
            "DOF",
            "mean",
            "RMS (alternating)",
            "strongest line",
            "its amplitude",
        ],
        &rows,
    );
    figure(
        &mut page,
        &dir.join("solve/spectrum.svg"),
        "Lines of the element coordinates",
    );
    if let Some(a) = swept {
        run_up(&mut page, dir, a);
    }
    page.finish()
}

fn overview(page: &mut HtmlReport, scene: &Scene, scene_text: &str, a: &TorusSolveAnalysis) {
    page.facts(&[
        ("scene", scene.file.clone()),
        ("description", scene.description.clone().unwrap_or_default()),
        ("speed", format!("{} {}", speed_text(a.speed), a.speed_unit)),
        ("basis", format!("several base frequencies: {}", a.why)),
        ("lines", a.lines.to_string()),
        ("relative residual", format!("{:.1e}", a.relative_residual)),
    ]);
    let ok = a.converged && a.caps_stopped.is_none();
    let text = match (&a.caps_stopped, a.converged) {
        (Some(why), _) => format!("automatic caps stopped above the tolerance: {why}"),
        (None, true) => "converged".to_string(),
        (None, false) => "NOT CONVERGED: the lines below are the last iterate".to_string(),
    };
    page.status(ok, &text);
    let rows: Vec<Vec<String>> = a
        .bases
        .iter()
        .map(|b| {
            vec![
                b.name.clone(),
                speed_text(b.order),
                format!("{:.2}", b.hz.unwrap_or(f64::NAN)),
                b.cap.to_string(),
                b.samples.to_string(),
                b.estimate
                    .map_or("not estimated".into(), |e| format!("{e:.1e}")),
            ]
        })
        .collect();
    page.table(
        &["base", "order", "Hz", "cap", "grid", "truncation estimate"],
        &rows,
    );
    let crate::torus::TorusStability::NotComputed { reason } = &a.stability;
    page.paragraph(&format!("Stability: {reason}"));
    page.details("scene file", scene_text);
}

fn lines_table(page: &mut HtmlReport, what: &str, s: &Spectrum) {
    page.paragraph(&format!(
        "{what}: mean {:.4e}, RMS of the alternating part {:.4e}",
        s.mean, s.rms
    ));
    let rows: Vec<Vec<String>> = s
        .lines
        .iter()
        .take(TABLE_LINES)
        .map(|l| {
            vec![
                l.label.clone(),
                speed_text(l.order),
                format!("{:.2}", l.hz),
                format!("{:.4e}", l.amplitude),
                format!("{:.1}", l.phase.to_degrees()),
            ]
        })
        .collect();
    page.table(&["line", "order", "Hz", "amplitude", "phase (deg)"], &rows);
}

fn run_up(page: &mut HtmlReport, dir: &std::path::Path, a: &TorusSweepAnalysis) {
    page.heading("Run-up");
    let failures = a.failures();
    page.status(
        failures == 0,
        &format!(
            "{} points, {failures} not converged or skipped (marked in sweep/points.csv)",
            a.points.len()
        ),
    );
    let rows: Vec<Vec<String>> = a
        .points
        .iter()
        .filter(|p| !p.converged)
        .map(|p| vec![speed_text(p.speed), format!("{:.1e}", p.relative_residual)])
        .chain(
            a.skipped
                .iter()
                .map(|(s, why)| vec![speed_text(*s), why.clone()]),
        )
        .collect();
    if !rows.is_empty() {
        page.table(
            &[
                &format!("speed ({})", a.speed_unit),
                "relative residual / reason",
            ],
            &rows,
        );
    }
    let rows: Vec<Vec<String>> = a
        .order_cuts
        .iter()
        .map(|c| {
            vec![
                c.element.clone(),
                c.label.clone(),
                speed_text(c.order),
                format!("{:.4e}", c.peak.0),
                speed_text(c.peak.1),
            ]
        })
        .collect();
    page.table(
        &[
            "element",
            "line",
            "order",
            "peak",
            &format!("at ({})", a.speed_unit),
        ],
        &rows,
    );
    figure(page, &dir.join("sweep/order_cuts.svg"), "Order cuts");
    figure(
        page,
        &dir.join("sweep/waterfall.svg"),
        "Waterfall: every line at its order, sidebands grey",
    );
}

/// Inlines the SVG at `path`, or says why not.
fn figure(page: &mut HtmlReport, path: &std::path::Path, caption: &str) {
    match std::fs::read_to_string(path) {
        Ok(svg) => {
            if let Err(e) = page.figure(&svg, caption) {
                page.paragraph(&e);
            }
        }
        Err(_) => page.paragraph(&format!("{caption}: no plot (nothing finite to draw)")),
    }
}
