//! `hbal solve`: solve one scene with its (or the given) solver, from the linear solution or a
//! `--start` file, compute the orbit's Floquet stability ([`hbal::analysis::solve`]), print a
//! summary or one JSON object (the analysis's serde form), and optionally write
//! harmonics.csv, time_series.csv and SVG plots.

use super::{load, start, Failure, SolverArgs};
use anyhow::Context;
use hbal::analysis::{SolveAnalysis, SolveNote, SolveSettings, StabilityOutcome};
use hbal::scene::Scene;
use std::path::Path;

/// Options of `hbal solve` besides the solver overrides.
pub(crate) struct SolveOptions<'a> {
    pub(crate) start: Option<&'a Path>,
    pub(crate) stability: bool,
    /// Fall back to the other solvers and homotopies where the scene's method fails.
    pub(crate) fallback: bool,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
}

pub(crate) fn solve(path: &Path, args: &SolverArgs, opts: SolveOptions) -> Result<u8, Failure> {
    let as_json = opts.json;
    let scene = load(path, args)?;
    if scene.torus.is_some() {
        super::torus_solve::refuse_flags(&[
            ("--start", opts.start.is_some()),
            ("--no-fallback", !opts.fallback),
        ])?;
        return super::torus_solve::solve(&scene, as_json, opts.out);
    }
    if let Some(dir) = opts.out {
        hbal::render::prepare_out(dir, &hbal::render::solve_files())
            .map_err(|e| super::failure(e, &scene.file))?;
    }
    let start = opts.start.map(|p| start::read(p, &scene)).transpose()?;
    if let (Some(file), Some(s)) = (opts.start, &start) {
        start_notes(&scene, file, s);
    }
    if let Some(dir) = opts.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--out: cannot create {}", dir.display()))?;
    }
    let settings = SolveSettings {
        start: start
            .zip(opts.start)
            .map(|(s, p)| (s.harmonics, p.display().to_string())),
        stability: opts.stability,
        fallback: opts.fallback,
        formulation: args.formulation,
    };
    let a = hbal::analysis::solve(&scene, &settings).map_err(|e| super::failure(e, &scene.file))?;
    if as_json {
        say!("{}", a.to_json());
    } else {
        super::solve_text::print(&scene, &a, opts.stability);
    }
    if let Some(dir) = opts.out {
        write_files(&scene, &a, dir, as_json)?;
    }
    print_messages(&scene, &a, opts.start);
    Ok(a.exit_code())
}

/// The notes on a `--start` file computed at another speed or with more harmonics.
fn start_notes(scene: &Scene, file: &Path, s: &hbal::analysis::StartRecord) {
    if let Some(w) = s.omega {
        let here = scene.basis.omega();
        if (w - here).abs() > 1e-9 * here {
            eprintln!(
                "note: --start {} was computed at {w} rad/s; the scene is at {here} rad/s",
                file.display()
            );
        }
    }
    if s.dropped_orders > 0 {
        eprintln!(
            "note: --start {}: {} harmonic order(s) above H = {} dropped",
            file.display(),
            s.dropped_orders,
            scene.basis.harmonics()
        );
    }
}

/// The files of `--out DIR` ([`hbal::render::write_solve_files`]), and what was written.
fn write_files(scene: &Scene, a: &SolveAnalysis, dir: &Path, as_json: bool) -> Result<(), Failure> {
    let mut warnings = Vec::new();
    let written = hbal::render::write_solve_files(scene, a, dir, &mut warnings)
        .map_err(|e| super::failure(e, &scene.file))?;
    super::print_warnings(&warnings);
    if !as_json {
        say!("  wrote {} to {}", written.join(", "), dir.display());
    }
    Ok(())
}

/// The errors of an unconverged solve and of automatic harmonics stopped at the cap.
fn report_failures(scene: &Scene, a: &SolveAnalysis) {
    if !a.solution.is_converged() {
        eprintln!(
            "error: {}: the solve did not converge: {}",
            scene.file, a.solution.termination
        );
    }
    if let Some(record) = a.auto.as_ref().filter(|r| r.capped) {
        let (auto, levels) = (&record.settings, &record.levels);
        // The quantity that limits it, where the estimate has one.
        let limiting = match &a.estimate {
            Some(Ok(e)) => e
                .worst_quantity
                .map(|q| {
                    format!(
                        "; worst quantity {} {:.1e} of its range",
                        q.quantity.name(&scene.model),
                        q.error
                    )
                })
                .unwrap_or_default(),
            _ => String::new(),
        };
        if let Some(why) = &record.stopped {
            eprintln!(
                "error: {}: automatic harmonics stopped before the tolerance {:.0e}: {why}; H = {} is reported (estimated error of {} {:.1e}){limiting}",
                scene.file,
                auto.tolerance,
                levels.last().map_or(0, |l| l.harmonics),
                auto.control.what(),
                levels.last().map_or(f64::NAN, |l| l.estimate),
            );
            return;
        }
        eprintln!(
            "error: {}: automatic harmonics: the estimated error of {} {:.1e} is above the tolerance {:.0e} at the cap H = {} (harmonics.max){limiting}",
            scene.file,
            auto.control.what(),
            levels.last().map_or(f64::NAN, |l| l.estimate),
            auto.tolerance,
            levels.last().map_or(0, |l| l.harmonics),
        );
    }
}

/// The notes, warnings and failures of `a` (a solve of `scene`, from the start file `start`)
/// on stderr.
pub(crate) fn print_messages(scene: &Scene, a: &SolveAnalysis, start: Option<&Path>) {
    for note in &a.notes {
        match (note, start) {
            (SolveNote::StartUnused, Some(file)) => eprintln!(
                "note: --start {} is not used: the exact piecewise solution needs no start",
                file.display()
            ),
            _ => eprintln!("note: {}: {note}", scene.file),
        }
    }
    match &a.stability {
        StabilityOutcome::Computed(f) if !f.is_stable() => eprintln!(
            "warning: the converged orbit is unstable (max |μ| = {:.6}): a time simulation would leave it",
            f.max_abs()
        ),
        StabilityOutcome::Failed(e) => {
            eprintln!("error: {}: stability computation failed: {e}", scene.file)
        }
        _ => {}
    }
    report_failures(scene, a);
}
