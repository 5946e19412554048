//! `hbal compare`: runs the library's comparison of every solver (or the one of `--method`)
//! with the time-domain reference ([`hbal::analysis::compare`]) and prints a table (or one
//! JSON object) of results, timings and errors against the time domain; with `--out` the
//! residual histories as a plot.

use super::{load, Failure, SolverArgs};
use hbal::analysis::{CompareAnalysis, CompareSettings};
use std::path::Path;

pub(crate) fn compare(
    path: &Path,
    args: &SolverArgs,
    as_json: bool,
    out: Option<&Path>,
) -> Result<u8, Failure> {
    let scene = load(path, args)?;
    if let Some(dir) = out {
        hbal::render::prepare_out(dir, &hbal::render::compare_files())
            .map_err(|e| super::failure(e, &scene.file))?;
    }
    let settings = CompareSettings {
        methods: args
            .method
            .as_ref()
            .map(|_| vec![scene.method.name().to_string()]),
        tolerance: args.tolerance,
        formulation: args.formulation,
    };
    let a =
        hbal::analysis::compare(&scene, &settings).map_err(|e| super::failure(e, &scene.file))?;
    if let Some(auto) = &a.auto {
        eprintln!(
            "note: harmonics: auto, tolerance {:.0e}{}: every method at H = {} (error estimate {:.1e}{})",
            auto.settings.tolerance,
            auto.settings.control.pick("", " on the harmonics 0..H"),
            a.basis.harmonics(),
            auto.estimate,
            if auto.capped { ", above the tolerance at the cap" } else { "" }
        );
    }
    if as_json {
        say!("{}", a.to_json());
    } else {
        table(&a);
    }
    if let Some(dir) = out {
        let mut warnings = Vec::new();
        hbal::render::write_compare_files(dir, &a, &mut warnings)
            .map_err(|e| super::failure(e, &scene.file))?;
        super::print_warnings(&warnings);
    }
    if a.exit_code() != 0 {
        eprintln!(
            "error: {}: no method converged (the table and the time-domain reference stand)",
            a.file
        );
    }
    Ok(a.exit_code())
}

/// The time domain's line and the table of methods.
fn table(a: &CompareAnalysis) {
    let td = &a.time_domain;
    say!(
        "{}: time domain (from {}) {:?} after {} periods, {} steps, {:.3} ms",
        a.file,
        if a.started_on_hb_orbit {
            "the HB orbit"
        } else {
            "rest"
        },
        td.stop,
        td.periods,
        td.steps,
        td.wall_time.as_secs_f64() * 1e3
    );
    say!("| method | result | iterations | wall | error vs time domain | worst quantity (dynamic part, of its range) |");
    say!("|---|---|---:|---:|---:|---|");
    for (i, m) in a.methods.iter().enumerate() {
        let worst = match (m.worst_quantity, a.quantity_name(i)) {
            (Some(q), Some(name)) => format!("{name} {:.2e}", q.error),
            _ => "–".into(),
        };
        say!(
            "| {} | {} | {} | {:.3} ms | {:.2e} | {worst} |",
            m.method,
            m.solution.termination,
            m.solution.stats.iterations,
            m.seconds * 1e3,
            m.error,
        );
    }
}
