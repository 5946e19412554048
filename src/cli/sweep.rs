//! `hbal sweep` (without `--parameter`): parses the options, runs the library's speed sweep
//! ([`hbal::analysis::sweep`]) with the progress bar, and renders its result as JSON, as the
//! summary ([`super::sweep_text`]) and as files in `--out` ([`hbal::render::write_sweep_files`]).

use super::{load, start, Failure, SolverArgs};
use hbal::analysis::{SweepAnalysis, SweepSettings, SweepStart};
use std::path::Path;

/// Options of a speed sweep besides the solver overrides.
pub(crate) struct SweepOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: f64,
    pub(crate) start: Option<&'a Path>,
    pub(crate) stability: bool,
    /// The orbit of the points' stability (`--stability-orbit`).
    pub(crate) orbit: hbal::stability::Orbit,
    pub(crate) max_points: Option<usize>,
    pub(crate) max_step: f64,
    /// Evenly spaced speeds of a sweep with the exact piecewise solution (no continuation).
    pub(crate) points: usize,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
    /// Switch to the branches leaving the main one at its branch points and period doublings.
    pub(crate) all_branches: bool,
    /// Estimate the error of every point against 2H.
    pub(crate) error_estimate: bool,
    /// The element or DOF the order-cut plot and the waterfall show.
    pub(crate) output: Option<&'a str>,
    /// `--dofs`: the DOFs whose harmonics and plots are written.
    pub(crate) dofs: Option<&'a str>,
}

impl SweepOptions<'_> {
    /// The library's settings of these options, the start harmonics read from their file.
    fn settings(&self, args: &SolverArgs, start: Option<SweepStart>) -> SweepSettings {
        SweepSettings {
            from: self.from,
            start,
            stability: self.stability,
            orbit: self.orbit,
            max_points: self.max_points,
            max_step: self.max_step,
            points: self.points,
            all_branches: self.all_branches,
            error_estimate: self.error_estimate,
            formulation: args.formulation,
            tolerance: args.tolerance,
            output: self.output.map(str::to_string),
            dofs: self.dofs.map(str::to_string),
            ..SweepSettings::to(self.to)
        }
    }
}

pub(crate) fn sweep(path: &Path, args: &SolverArgs, opts: SweepOptions) -> Result<u8, Failure> {
    let as_json = opts.json;
    let scene = load(path, args)?;
    if scene.torus.is_some() {
        super::torus_solve::refuse_flags(&[
            ("--start", opts.start.is_some()),
            ("--all-branches", opts.all_branches),
            ("--max-points", opts.max_points.is_some()),
            ("--dofs", opts.dofs.is_some()),
            (
                "--stability-orbit",
                opts.orbit != hbal::stability::Orbit::Exact,
            ),
        ])?;
        let torus = super::torus_sweep::TorusSweepOptions {
            from: opts.from,
            to: opts.to,
            points: opts.points,
            json: as_json,
            out: opts.out,
            output: opts.output,
        };
        return super::torus_sweep::sweep(&scene, torus);
    }
    let start = opts.start.map(|p| start::read(p, &scene)).transpose()?;
    let start = start.zip(opts.start).map(|(s, file)| SweepStart {
        harmonics: s.harmonics,
        omega: s.omega,
        label: file.display().to_string(),
    });
    let settings = opts.settings(args, start);
    hbal::analysis::check_sweep(&scene, &settings).map_err(|e| super::failure(e, &scene.file))?;
    if let Some(dir) = opts.out {
        hbal::render::prepare_sweep_out(dir, &scene, opts.dofs)
            .map_err(|e| super::failure(e, &scene.file))?;
    }
    let bar = super::progress::Progress::new("sweep", as_json);
    let analysis = hbal::analysis::sweep(&scene, &settings, &mut &bar)
        .map_err(|e| super::failure(e, &scene.file))?;
    bar.finish();
    if as_json {
        say!("{}", analysis.to_json());
    } else {
        super::sweep_text::print(&scene, &analysis, opts.out.is_some());
    }
    if let Some(dir) = opts.out {
        let mut warnings = Vec::new();
        hbal::render::write_sweep_files(dir, &scene, &analysis, &mut warnings)
            .map_err(|e| super::failure(e, &scene.file))?;
        super::print_warnings(&warnings);
    }
    print_messages(&analysis);
    Ok(analysis.exit_code())
}

/// The notes of the sweep, and the failures and warnings that mark it, on stderr.
pub(crate) fn print_messages(a: &SweepAnalysis) {
    let (file, unit) = (&a.file, &a.unit);
    for note in &a.notes {
        eprintln!("note: {}", note.describe(unit));
    }
    if a.branch.stop != hbal::continuation::BranchStop::Reached {
        eprintln!("error: {file}: the branch stopped: {}", a.branch.stop);
    }
    if let Some(omega) = a.non_finite_stability() {
        eprintln!(
            "error: {file}: stability at {} {unit}: non-finite Floquet multiplier",
            a.speed(omega)
        );
    }
    if let (Some((e, w)), Some(auto)) = (a.above_tolerance(), a.auto) {
        eprintln!(
            "warning: {file}: error estimate{} up to {e:.1e} (at {} {unit}), above the tolerance {:.0e} of the H = {} chosen at the first speed: start the sweep there or raise harmonics.count",
            auto.control.pick("", " of the harmonics 0..H"),
            a.speed(w),
            auto.tolerance,
            a.branch.harmonics
        );
    }
    for b in a.failed_branches() {
        eprintln!(
            "error: {file}: a switched branch stopped: {}",
            super::sweep_summary::secondary_line(b, unit, |w| a.speed(w))
        );
    }
}
