//! `hbal report SCENE [--from A --to B] --out DIR`: the library's report
//! ([`hbal::render::report`]: `report.html` with the solve, the run-up and the natural
//! frequencies, and their files in `DIR/solve`, `DIR/sweep`, `DIR/modes`), with its stages on
//! stderr and the parts' notes and failures as the subcommands print them.

use super::{Failure, SolverArgs};
use hbal::render::{ReportParts, ReportSettings};
use std::path::Path;

/// Options of `hbal report` besides the solver overrides.
pub(crate) struct ReportOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: Option<f64>,
    pub(crate) stability: bool,
    pub(crate) out: &'a Path,
    pub(crate) output: Option<&'a str>,
    /// The run-up's `--max-step`, `--max-points` and `--points`.
    pub(crate) resolution: (Option<f64>, Option<usize>, Option<usize>),
}

/// The stages on stderr (`report: solving ...`).
struct Stages;

impl hbal::analysis::Observer for Stages {
    fn stage(&mut self, what: &str) {
        eprintln!("report: {what}");
    }
}

pub(crate) fn report(path: &Path, args: &SolverArgs, opts: ReportOptions) -> Result<u8, Failure> {
    let scene = super::load(path, args)?;
    let scene_text = std::fs::read_to_string(path).unwrap_or_default();
    let settings = ReportSettings {
        from: opts.from,
        to: opts.to,
        stability: opts.stability,
        output: opts.output.map(str::to_string),
        formulation: args.formulation,
        tolerance: args.tolerance,
        max_step: opts.resolution.0,
        max_points: opts.resolution.1,
        points: opts.resolution.2,
        ..ReportSettings::default()
    };
    let r = hbal::render::report(&scene, &scene_text, &settings, opts.out, &mut Stages)
        .map_err(|e| super::failure(e, &scene.file))?;
    if let ReportParts::Periodic(parts) = &r.parts {
        // Their notes and failures as `hbal solve` and `hbal sweep` print them.
        if let Some(a) = &parts.solved.result {
            super::solve::print_messages(&scene, a, None);
        }
        if let Some(a) = parts.swept.as_ref().and_then(|p| p.result.as_ref()) {
            super::sweep::print_messages(a);
        }
    }
    super::print_warnings(&r.warnings);
    for e in r.errors() {
        eprintln!("error: {e}");
    }
    say!("wrote {}", r.file.display());
    Ok(r.exit_code)
}
