//! `hbal report SCENE [--from A --to B] --out DIR`: one self-contained `report.html` with the
//! scene, its settings, the solve at the scene's speed (convergence, error estimate,
//! stability, DOF and element tables, time series and spectrum), with `--from`/`--to` the
//! run-up (order cuts, waterfall, frequency responses, contact loss), and the natural
//! frequencies with the Campbell diagram. It runs `solve`, `sweep` and `modes` into
//! `DIR/solve`, `DIR/sweep` and `DIR/modes` (their CSV files stay there) and builds the page
//! from their JSON documents and SVG plots (see `report_html`).

use super::{modes, solve, sweep, Failure, SolverArgs};
use serde_json::Value;
use std::path::Path;

/// Options of `hbal report` besides the solver overrides.
pub(crate) struct ReportOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: Option<f64>,
    pub(crate) stability: bool,
    pub(crate) out: &'a Path,
    pub(crate) output: Option<&'a str>,
}

/// One part of the report: its JSON document, or why there is none, and its exit code.
pub(crate) struct Part {
    pub(crate) doc: Option<Value>,
    pub(crate) error: Option<String>,
    pub(crate) code: u8,
}

impl Part {
    fn run(f: impl FnOnce(&mut Option<Value>) -> Result<u8, Failure>) -> Part {
        let mut doc = None;
        match f(&mut doc) {
            Ok(code) => Part {
                doc,
                error: None,
                code,
            },
            Err(e) => Part {
                doc,
                error: Some(format!("{:#}", e.error)),
                code: e.code,
            },
        }
    }
}

pub(crate) fn report(path: &Path, args: &SolverArgs, opts: ReportOptions) -> Result<u8, Failure> {
    // Bad input first: the scene, the speed range, the output name and --out.
    let scene = super::load(path, args)?;
    if opts.from.is_some() && opts.to.is_none() {
        return Err(anyhow::anyhow!("--from needs --to (the run-up's end speed)").into());
    }
    if opts.output.is_some() && opts.to.is_none() {
        return Err(anyhow::anyhow!("--output chooses the run-up's plots: give --to").into());
    }
    for (name, value) in [("--from", opts.from), ("--to", opts.to)] {
        if let Some(v) = value {
            hbal::analysis::check_speed(&scene, name, v, false)
                .map_err(|e| anyhow::anyhow!("{e}"))?;
        }
    }
    hbal::analysis::shown_output(&scene, opts.output)?;
    for dof in scene.model.dof_names() {
        super::file_name_part(dof, "DOF")?;
    }
    super::prepare_out(opts.out)?;
    let scene_text = std::fs::read_to_string(path).unwrap_or_default();
    let dir = opts.out;
    eprintln!("report: solving {} at its speed", scene.file);
    let solved = Part::run(|doc| {
        solve::solve(
            path,
            args,
            solve::SolveOptions {
                start: None,
                stability: opts.stability,
                fallback: true,
                json: true,
                out: Some(&dir.join("solve")),
                capture: Some(doc),
            },
        )
    });
    if solved.doc.is_none() && solved.code == 2 {
        // Bad input the checks above did not catch: nothing to report.
        return Err(
            anyhow::anyhow!("{}", solved.error.unwrap_or_else(|| "solve failed".into())).into(),
        );
    }
    let swept = opts.to.map(|to| {
        eprintln!(
            "report: run-up to {} {}",
            super::speed_text(to),
            scene.speed_unit
        );
        Part::run(|doc| {
            sweep::sweep(
                path,
                args,
                sweep::SweepOptions {
                    from: opts.from,
                    to,
                    start: None,
                    stability: opts.stability,
                    orbit: hbal::stability::Orbit::Exact,
                    max_points: None,
                    max_step: 0.5,
                    points: 101,
                    json: true,
                    out: Some(&dir.join("sweep")),
                    all_branches: false,
                    error_estimate: true,
                    output: opts.output,
                    capture: Some(doc),
                    dofs: None,
                },
            )
        })
    });
    eprintln!("report: natural frequencies");
    let speed = scene.basis.omega() / scene.omega_per_speed;
    let (lo, hi) = match (opts.from, opts.to) {
        (Some(a), Some(b)) => (a.min(b), a.max(b)),
        (None, Some(b)) => (speed.min(b), speed.max(b)),
        _ => (0.0, 2.0 * speed),
    };
    let moded = Part::run(|doc| {
        modes::modes(
            path,
            args,
            modes::ModesOptions {
                from: Some(lo),
                to: Some(hi),
                max_hz: None,
                json: true,
                out: Some(&dir.join("modes")),
                capture: Some(doc),
            },
        )
    });
    let html = super::report_html::build(&super::report_html::Inputs {
        scene: &scene,
        scene_text: &scene_text,
        dir,
        solved: &solved,
        swept: swept.as_ref(),
        moded: &moded,
    });
    let file = dir.join("report.html");
    std::fs::write(&file, html).map_err(|e| {
        Failure::from(anyhow::anyhow!(
            "--out: cannot write {}: {e}",
            file.display()
        ))
    })?;
    let code = [Some(&solved), swept.as_ref(), Some(&moded)]
        .into_iter()
        .flatten()
        .map(|p| p.code)
        .max()
        .unwrap_or(0);
    for part in [Some(&solved), swept.as_ref(), Some(&moded)]
        .into_iter()
        .flatten()
    {
        if let Some(e) = &part.error {
            eprintln!("error: {e}");
        }
    }
    say!("wrote {}", file.display());
    // A part that failed on bad input (e.g. modes of a model it cannot linearise) is reported
    // in the page; the report itself is a numerical failure then, not bad input.
    Ok(code.min(1))
}
