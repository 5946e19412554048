//! `hbal sweep --parameter <field>`: parses the options, runs the library's parameter sweep
//! ([`hbal::analysis::parameter_sweep`]) with the progress bar, and renders its result as
//! JSON, a summary, and branch.csv with one parameter-response SVG per reported DOF.

use super::{Failure, SolverArgs};
use hbal::analysis::{ParameterSweepAnalysis, ParameterSweepSettings};
use hbal::scene::Scene;
use std::path::Path;

/// Options of a `--parameter` sweep.
pub(crate) struct ParameterSweep<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: f64,
    pub(crate) points: usize,
    pub(crate) solver: &'a SolverArgs,
    pub(crate) start: Option<&'a Path>,
    pub(crate) stability: bool,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
    /// `--dofs` ([`hbal::analysis::reported_dofs`]).
    pub(crate) dofs: Option<&'a str>,
}

pub(crate) fn parameter_sweep(
    path: &Path,
    name: &str,
    opts: ParameterSweep,
) -> Result<u8, Failure> {
    let Some(from) = opts.from else {
        return Err(anyhow::anyhow!("--parameter needs --from").into());
    };
    if opts.start.is_some() {
        let why = "--start applies to speed sweeps, not to a --parameter sweep";
        return Err(anyhow::anyhow!(why).into());
    }
    let file = path.display().to_string();
    let text = hbal::scene::bounded_read::read_text(path)
        .map_err(|e| anyhow::anyhow!("{file}: cannot read the file: {e}"))?;
    let doc = Scene::parse_value(&text, &file)?;
    let settings = ParameterSweepSettings {
        parameter: name.to_string(),
        from,
        to: opts.to,
        points: opts.points,
        stability: opts.stability,
        overrides: opts.solver.overrides(),
        dofs: opts.dofs.map(str::to_string),
        cancel: Default::default(),
    };
    hbal::analysis::check_parameter_sweep(&doc, &file, &settings)
        .map_err(|e| super::failure(e, &file))?;
    if let Some(dir) = opts.out {
        // The DOF names of the first value make the file names.
        let mut first = doc.clone();
        let mut files = vec!["branch.csv".to_string()];
        if hbal::scene::set_parameter(&mut first, name, from).is_ok() {
            if let Ok(scene) = Scene::from_value(first, &file) {
                files = hbal::render::parameter_sweep_files(scene.model.dof_names())
                    .map_err(|e| super::failure(e, &file))?;
            }
        }
        hbal::render::prepare_out(dir, &files).map_err(|e| super::failure(e, &file))?;
    }
    let bar = super::progress::Progress::new("parameter sweep", opts.json);
    let a = hbal::analysis::parameter_sweep(&doc, &file, &settings, &mut &bar)
        .map_err(|e| super::failure(e, &file))?;
    bar.finish();
    if let Some(auto) = &a.auto {
        eprintln!(
            "note: harmonics: auto, tolerance {:.0e}{}: H = {} (error estimate {:.1e} at {name} = {from}{}), kept for every value and not checked at the others",
            auto.settings.tolerance,
            auto.settings.control.pick("", " on the harmonics 0..H"),
            auto.harmonics,
            auto.estimate,
            if auto.capped { ", above the tolerance at the cap" } else { "" }
        );
    }
    if opts.json {
        say!("{}", a.to_json());
    } else {
        summary(&a);
    }
    if let Some(dir) = opts.out {
        let mut warnings = Vec::new();
        hbal::render::write_parameter_sweep_files(dir, &a, &mut warnings)
            .map_err(|e| super::failure(e, &file))?;
        super::print_warnings(&warnings);
    }
    if a.exit_code() != 0 {
        eprintln!("error: {file}: the sweep stopped: {}", a.branch.stop);
    }
    Ok(a.exit_code())
}

/// The summary: the values, the time and the stop, and every stability change.
fn summary(a: &ParameterSweepAnalysis) {
    let s = &a.settings;
    say!(
        "{}: {} values of {} from {} to {} in {:.1} ms: {}",
        a.file,
        a.branch.points.len(),
        s.parameter,
        s.from,
        s.to,
        a.seconds * 1e3,
        a.branch.stop
    );
    for p in a.branch.points.iter().filter(|p| p.bifurcation.is_some()) {
        say!(
            "  stability change ({:?}) at {} = {}",
            p.bifurcation.unwrap_or(hbal::stability::Bifurcation::Fold),
            s.parameter,
            p.parameter
        );
    }
}
