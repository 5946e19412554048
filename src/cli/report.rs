//! `hbal report SCENE [--from A --to B] --out DIR`: one self-contained `report.html` with the
//! scene, its settings, the solve at the scene's speed (convergence, error estimate,
//! stability, DOF and element tables, time series and spectrum), with `--from`/`--to` the
//! run-up (order cuts, waterfall, frequency responses, contact loss), and the natural
//! frequencies with the Campbell diagram. It runs the library's solve, sweep and modes
//! analyses, writes their files into `DIR/solve`, `DIR/sweep` and `DIR/modes` as the
//! subcommands do, and builds the page from the typed results and those plots
//! (see `report_html`).

use super::{Failure, SolverArgs};
use hbal::analysis::{ModesAnalysis, ModesSettings, SolveAnalysis, SolveSettings};
use hbal::analysis::{SweepAnalysis, SweepSettings};
use hbal::scene::Scene;
use std::path::Path;

/// Options of `hbal report` besides the solver overrides.
pub(crate) struct ReportOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: Option<f64>,
    pub(crate) stability: bool,
    pub(crate) out: &'a Path,
    pub(crate) output: Option<&'a str>,
}

/// One part of the report: its result, or why there is none, and its exit code.
pub(crate) struct Part<T> {
    pub(crate) result: Option<T>,
    pub(crate) error: Option<String>,
    pub(crate) code: u8,
}

impl<T> Part<T> {
    /// The part from an analysis and the files written from it: the result with its exit
    /// code (and `failed`'s message where that is not 0), or the error.
    fn run(
        analysis: Result<T, Failure>,
        code: impl Fn(&T) -> u8,
        failed: &str,
        write: impl FnOnce(&T) -> Result<(), Failure>,
    ) -> Part<T> {
        match analysis.and_then(|a| write(&a).map(|()| a)) {
            Ok(a) => {
                let code = code(&a);
                let error = (code != 0 && !failed.is_empty()).then(|| failed.to_string());
                Part {
                    result: Some(a),
                    error,
                    code,
                }
            }
            Err(e) => Part {
                result: None,
                error: Some(format!("{:#}", e.error)),
                code: e.code,
            },
        }
    }
}

pub(crate) fn report(path: &Path, args: &SolverArgs, opts: ReportOptions) -> Result<u8, Failure> {
    let scene = super::load(path, args)?;
    let scene_text = std::fs::read_to_string(path).unwrap_or_default();
    if scene.torus.is_some() {
        return super::torus_report::report(&scene, &scene_text, &opts);
    }
    let scene = check(scene, &opts)?;
    let dir = opts.out;
    eprintln!("report: solving {} at its speed", scene.file);
    let solved = solve_part(&scene, args, &opts);
    if solved.result.is_none() && solved.code == 2 {
        // Bad input the checks above did not catch: nothing to report.
        let why = solved.error.unwrap_or_else(|| "solve failed".into());
        return Err(anyhow::anyhow!("{why}").into());
    }
    let swept = opts.to.map(|to| {
        eprintln!(
            "report: run-up to {} {}",
            super::speed_text(to),
            scene.speed_unit
        );
        sweep_part(&scene, args, &opts, to)
    });
    eprintln!("report: natural frequencies");
    let moded = modes_part(&scene, args, &opts);
    let html = super::report_html::build(&super::report_html::Inputs {
        scene: &scene,
        scene_text: &scene_text,
        dir,
        solved: &solved,
        swept: swept.as_ref(),
        moded: &moded,
    });
    let file = dir.join("report.html");
    std::fs::write(&file, html)
        .map_err(|e| anyhow::anyhow!("--out: cannot write {}: {e}", file.display()))?;
    let parts = [
        (solved.code, solved.error.as_ref()),
        swept
            .as_ref()
            .map_or((0, None), |p| (p.code, p.error.as_ref())),
        (moded.code, moded.error.as_ref()),
    ];
    for e in parts.iter().filter_map(|p| p.1) {
        eprintln!("error: {e}");
    }
    say!("wrote {}", file.display());
    // A part that failed on bad input (e.g. modes of a model it cannot linearise) is reported
    // in the page; the report itself is a numerical failure then, not bad input.
    Ok(parts.iter().map(|p| p.0).max().unwrap_or(0).min(1))
}

/// Bad input first: the scene, the speed range, the output name and --out.
fn check(scene: Scene, opts: &ReportOptions) -> Result<Scene, Failure> {
    if opts.from.is_some() && opts.to.is_none() {
        return Err(anyhow::anyhow!("--from needs --to (the run-up's end speed)").into());
    }
    if opts.output.is_some() && opts.to.is_none() {
        return Err(anyhow::anyhow!("--output chooses the run-up's plots: give --to").into());
    }
    for (name, value) in [("--from", opts.from), ("--to", opts.to)] {
        if let Some(v) = value {
            hbal::analysis::check_speed(&scene, name, v, false)
                .map_err(|e| super::failure(e, &scene.file))?;
        }
    }
    hbal::analysis::shown_output(&scene, opts.output)
        .map_err(|e| super::failure(e, &scene.file))?;
    for dof in scene.model.dof_names() {
        super::file_name_part(dof, "DOF")?;
    }
    // report.html, and the parts' files in their folders.
    let out = opts.out;
    super::prepare_out(out, &["report.html".to_string()])?;
    super::prepare_out(&out.join("solve"), &super::solve_files())?;
    if opts.to.is_some() {
        let names = scene.model.dof_names();
        let reported = hbal::analysis::reported_dofs(&scene.model, None)
            .map_err(|e| super::failure(e, &scene.file))?;
        let files = super::sweep_files(reported.iter().map(|&i| &names[i]));
        super::prepare_out(&out.join("sweep"), &files)?;
    }
    super::prepare_out(&out.join("modes"), &super::modes_files())?;
    Ok(scene)
}

/// The solve at the scene's speed, its files in `DIR/solve`.
fn solve_part(scene: &Scene, args: &SolverArgs, opts: &ReportOptions) -> Part<SolveAnalysis> {
    let settings = SolveSettings {
        stability: opts.stability,
        formulation: args.formulation,
        ..SolveSettings::default()
    };
    let analysis =
        hbal::analysis::solve(scene, &settings).map_err(|e| super::failure(e, &scene.file));
    let dir = opts.out.join("solve");
    // Its notes and failures as `hbal solve` prints them.
    if let Ok(a) = &analysis {
        super::solve::print_messages(scene, a, None);
    }
    Part::run(analysis, SolveAnalysis::exit_code, "", |a| {
        super::solve::write_files(scene, a, &dir, true)
    })
}

/// The run-up to `to`, its files in `DIR/sweep`.
fn sweep_part(
    scene: &Scene,
    args: &SolverArgs,
    opts: &ReportOptions,
    to: f64,
) -> Part<SweepAnalysis> {
    let settings = SweepSettings {
        from: opts.from,
        stability: opts.stability,
        formulation: args.formulation,
        tolerance: args.tolerance,
        output: opts.output.map(str::to_string),
        ..SweepSettings::to(to)
    };
    let analysis = hbal::analysis::sweep(scene, &settings, &mut hbal::analysis::Silent)
        .map_err(|e| super::failure(e, &scene.file));
    let dir = opts.out.join("sweep");
    // Its notes and failures as `hbal sweep` prints them.
    if let Ok(a) = &analysis {
        super::sweep::print_messages(a);
    }
    Part::run(analysis, SweepAnalysis::exit_code, "", |a| {
        Ok(super::sweep_files::write(&dir, scene, a)?)
    })
}

/// The natural frequencies over the run-up's range (else 0 to twice the scene's speed), the
/// Campbell diagram in `DIR/modes`.
fn modes_part(scene: &Scene, args: &SolverArgs, opts: &ReportOptions) -> Part<ModesAnalysis> {
    let speed = scene.basis.omega() / scene.omega_per_speed;
    let (lo, hi) = match (opts.from, opts.to) {
        (Some(a), Some(b)) => (a.min(b), a.max(b)),
        (None, Some(b)) => (speed.min(b), speed.max(b)),
        _ => (0.0, 2.0 * speed),
    };
    let settings = ModesSettings {
        from: Some(lo),
        to: Some(hi),
        max_hz: None,
        formulation: args.formulation,
    };
    let analysis =
        hbal::analysis::modes(scene, &settings).map_err(|e| super::failure(e, &scene.file));
    let dir = opts.out.join("modes");
    let failed = match &analysis {
        Ok(a) => format!(
            "{}: the operating point did not converge ({}): no linearisation",
            scene.file, a.termination
        ),
        Err(_) => String::new(),
    };
    Part::run(analysis, ModesAnalysis::exit_code, &failed, |a| {
        let Some(nf) = &a.natural else { return Ok(()) };
        Ok(super::modes::write_outputs(
            &dir, scene, nf, &a.orders, a.range, a.per_unit,
        )?)
    })
}
