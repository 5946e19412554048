//! The report (`hbal report SCENE [--from A --to B] --out DIR`, Python's `hbal.report`): one
//! self-contained `report.html` with the scene, its settings, the solve at the scene's speed
//! (convergence, error estimate, stability, DOF and element tables, time series and
//! spectrum), with a run-up (`to`) its order cuts, waterfall, frequency responses and contact
//! loss, and the natural frequencies with the Campbell diagram. It runs the library's solve,
//! sweep and modes analyses, writes their files into `DIR/solve`, `DIR/sweep` and
//! `DIR/modes` as the subcommands do, and builds the page from the typed results and those
//! plots ([`super::report_html`]). A scene on several base frequencies has its own page
//! ([`super::torus_report`]).

use super::{prepare_out, speed_text};
use crate::analysis::{ModesAnalysis, ModesSettings, Observer, SolveAnalysis, SolveSettings};
use crate::analysis::{SweepAnalysis, SweepSettings, TorusSolveAnalysis, TorusSweepAnalysis};
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::Formulation;
use std::path::{Path, PathBuf};

/// What a report covers besides the scene's own speed.
#[derive(Debug, Clone, Default)]
pub struct ReportSettings {
    /// The run-up's start speed (default: the scene's), in the scene's speed unit.
    pub from: Option<f64>,
    /// The run-up's end speed: without it, no run-up.
    pub to: Option<f64>,
    /// Floquet stability of the solve and along the run-up.
    pub stability: bool,
    /// The output whose order cuts and waterfall are plotted (a DOF, `u(element)`), by default
    /// the first gear stage's transmission error.
    pub output: Option<String>,
    /// The unknowns of every analysis.
    pub formulation: Formulation,
    /// The run-up's solver tolerance (default: the scene's).
    pub tolerance: Option<f64>,
    /// The run-up's largest continuation step (scaled arclength; default 0.5: smaller gives
    /// more points).
    pub max_step: Option<f64>,
    /// The run-up's point limit (default the continuation's).
    pub max_points: Option<usize>,
    /// The run-up's evenly spaced speeds where it has them (several base frequencies: default
    /// 101; the exact piecewise method).
    pub points: Option<usize>,
    /// Stops the run-up at its next point (its branch so far is reported).
    pub cancel: crate::continuation::Cancel,
}

/// One part of the report: its result, or why there is none, and its exit code.
#[derive(Debug)]
pub struct Part<T> {
    /// The analysis, where it ran.
    pub result: Option<T>,
    /// Why it failed (or has nothing to show), where it did.
    pub error: Option<String>,
    /// Its exit code (0, 1 for a numerical failure, 2 for input it could not take).
    pub code: u8,
}

impl<T> Part<T> {
    /// The part from an analysis and the files written from it: the result with its exit
    /// code (and `failed`'s message where that is not 0), or the error.
    fn run(
        file: &str,
        analysis: Result<T>,
        code: impl Fn(&T) -> u8,
        failed: &str,
        write: impl FnOnce(&T) -> Result<()>,
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
                // A scene error names its file already.
                error: Some(match e {
                    Error::Scene(_) => e.to_string(),
                    _ => format!("{file}: {e}"),
                }),
                code: e.exit_code(),
            },
        }
    }
}

/// The analyses of the report of a periodic scene.
#[derive(Debug)]
pub struct PeriodicParts {
    /// The solve at the scene's speed.
    pub solved: Part<SolveAnalysis>,
    /// The run-up (with `to`).
    pub swept: Option<Part<SweepAnalysis>>,
    /// The natural frequencies.
    pub moded: Part<ModesAnalysis>,
}

/// The analyses of a report.
#[derive(Debug)]
pub enum ReportParts {
    /// A periodic scene: the solve, the run-up (with `to`) and the natural frequencies.
    Periodic(Box<PeriodicParts>),
    /// A scene on several base frequencies: the solve and the run-up (with `to`).
    Torus {
        /// The solve at the scene's speed.
        solved: Box<TorusSolveAnalysis>,
        /// The run-up.
        swept: Option<Box<TorusSweepAnalysis>>,
    },
}

/// A written report.
#[derive(Debug)]
pub struct Report {
    /// `DIR/report.html`.
    pub file: PathBuf,
    /// The analyses it shows.
    pub parts: ReportParts,
    /// Plots that could not be drawn.
    pub warnings: Vec<String>,
    /// 0, or 1 where a part failed numerically or failed on input it could not take (its
    /// page says why).
    pub exit_code: u8,
}

impl Report {
    /// Why the parts that failed failed.
    pub fn errors(&self) -> Vec<&str> {
        match &self.parts {
            ReportParts::Periodic(p) => [
                p.solved.error.as_deref(),
                p.swept.as_ref().and_then(|p| p.error.as_deref()),
                p.moded.error.as_deref(),
            ]
            .into_iter()
            .flatten()
            .collect(),
            ReportParts::Torus { .. } => Vec::new(),
        }
    }
}

/// Runs the analyses of the report of `scene` (whose text as read is `scene_text`) and writes
/// it into `out` (`report.html` and the parts' files in `out/solve`, `out/sweep`,
/// `out/modes`). Bad input (the speeds, the output, an unusable `out`, a solve that cannot
/// start) is an error before any work; a part that fails later is shown failed in the page
/// and sets [`Report::exit_code`] to 1. The observer hears the stages and the run-up's
/// progress; a report cancelled through [`ReportSettings::cancel`] is [`Error::Cancelled`]
/// before its page is written.
pub fn report(
    scene: &Scene,
    scene_text: &str,
    settings: &ReportSettings,
    out: &Path,
    observer: &mut dyn Observer,
) -> Result<Report> {
    if settings.from.is_some() && settings.to.is_none() {
        return Err(options("--from", "needs --to (the run-up's end speed)"));
    }
    if settings.output.is_some() && settings.to.is_none() {
        return Err(options("--output", "chooses the run-up's plots: give --to"));
    }
    if scene.torus.is_some() {
        return super::torus_report::report(scene, scene_text, settings, out, observer);
    }
    check(scene, settings, out)?;
    let mut warnings = Vec::new();
    observer.stage(&format!("solving {} at its speed", scene.file));
    let solved = solve_part(scene, settings, out, &mut warnings)?;
    let swept = match settings.to {
        Some(to) => {
            observer.stage(&format!(
                "run-up to {} {}",
                speed_text(to),
                scene.speed_unit
            ));
            cancelled(settings)?;
            Some(sweep_part(
                scene,
                settings,
                out,
                to,
                observer,
                &mut warnings,
            ))
        }
        None => None,
    };
    observer.stage("natural frequencies");
    cancelled(settings)?;
    let moded = modes_part(scene, settings, out, &mut warnings);
    cancelled(settings)?;
    let html = super::report_html::build(&super::report_html::Inputs {
        scene,
        scene_text,
        dir: out,
        solved: &solved,
        swept: swept.as_ref(),
        moded: &moded,
    });
    let file = out.join("report.html");
    std::fs::write(&file, html).map_err(|e| super::cannot_write(out, e))?;
    // A part that failed on bad input (e.g. modes of a model it cannot linearise) is reported
    // in the page; the report itself is a numerical failure then, not bad input.
    let codes = [
        solved.code,
        swept.as_ref().map_or(0, |p| p.code),
        moded.code,
    ];
    Ok(Report {
        file,
        parts: ReportParts::Periodic(Box::new(PeriodicParts {
            solved,
            swept,
            moded,
        })),
        warnings,
        exit_code: codes.into_iter().max().unwrap_or(0).min(1),
    })
}

/// [`Error::Cancelled`] where the caller cancelled the report (its observer or a failed law
/// set [`ReportSettings::cancel`]): no page for a report stopped half way.
pub(super) fn cancelled(settings: &ReportSettings) -> Result<()> {
    if settings.cancel.is_cancelled() {
        return Err(Error::Cancelled {
            what: "the report".into(),
        });
    }
    Ok(())
}

/// An [`Error::InvalidOptions`].
pub(super) fn options(option: &str, reason: &str) -> Error {
    Error::InvalidOptions {
        option: option.into(),
        reason: reason.into(),
    }
}

/// Bad input first: the speed range, the output name, the DOF names in file names and `out`
/// (`--from` and `--output` without `--to` are refused before, for every scene).
fn check(scene: &Scene, settings: &ReportSettings, out: &Path) -> Result<()> {
    for (name, value) in [("--from", settings.from), ("--to", settings.to)] {
        if let Some(v) = value {
            crate::analysis::check_speed(scene, name, v, false)?;
        }
    }
    if let Some(to) = settings.to {
        crate::analysis::check_sweep(scene, &sweep_settings(settings, to))?;
    }
    crate::analysis::shown_output(scene, settings.output.as_deref())?;
    for dof in scene.model.dof_names() {
        super::file_name_part(dof, "DOF")?;
    }
    // report.html, and the parts' files in their folders.
    prepare_out(out, &["report.html".to_string()])?;
    prepare_out(&out.join("solve"), &super::solve_files())?;
    if settings.to.is_some() {
        super::prepare_sweep_out(&out.join("sweep"), scene, None)?;
    }
    prepare_out(&out.join("modes"), &super::modes_files())
}

/// The solve at the scene's speed, its files in `out/solve`; bad input the checks before did
/// not catch is an error (nothing to report).
fn solve_part(
    scene: &Scene,
    settings: &ReportSettings,
    out: &Path,
    warnings: &mut Vec<String>,
) -> Result<Part<SolveAnalysis>> {
    let solve = SolveSettings {
        stability: settings.stability,
        formulation: settings.formulation,
        ..SolveSettings::default()
    };
    let analysis = match crate::analysis::solve(scene, &solve) {
        Err(e) if e.exit_code() == 2 => return Err(e),
        analysis => analysis,
    };
    let dir = out.join("solve");
    Ok(Part::run(
        &scene.file,
        analysis,
        SolveAnalysis::exit_code,
        "",
        |a| super::write_solve_files(scene, a, &dir, warnings).map(|_| ()),
    ))
}

/// The run-up's settings: the report's, the sweep's defaults for the rest.
fn sweep_settings(settings: &ReportSettings, to: f64) -> SweepSettings {
    let defaults = SweepSettings::to(to);
    SweepSettings {
        from: settings.from,
        stability: settings.stability,
        formulation: settings.formulation,
        tolerance: settings.tolerance,
        output: settings.output.clone(),
        cancel: settings.cancel.clone(),
        max_step: settings.max_step.unwrap_or(defaults.max_step),
        max_points: settings.max_points,
        points: settings.points.unwrap_or(defaults.points),
        ..defaults
    }
}

/// The run-up to `to`, its files in `out/sweep`.
fn sweep_part(
    scene: &Scene,
    settings: &ReportSettings,
    out: &Path,
    to: f64,
    observer: &mut dyn Observer,
    warnings: &mut Vec<String>,
) -> Part<SweepAnalysis> {
    let sweep = sweep_settings(settings, to);
    let dir = out.join("sweep");
    Part::run(
        &scene.file,
        crate::analysis::sweep(scene, &sweep, observer),
        SweepAnalysis::exit_code,
        "",
        |a| super::write_sweep_files(&dir, scene, a, warnings),
    )
}

/// The natural frequencies over the run-up's range (else 0 to twice the scene's speed), the
/// Campbell diagram in `out/modes`.
fn modes_part(
    scene: &Scene,
    settings: &ReportSettings,
    out: &Path,
    warnings: &mut Vec<String>,
) -> Part<ModesAnalysis> {
    let speed = scene.basis.omega() / scene.omega_per_speed;
    let (lo, hi) = match (settings.from, settings.to) {
        (Some(a), Some(b)) => (a.min(b), a.max(b)),
        (None, Some(b)) => (speed.min(b), speed.max(b)),
        _ => (0.0, 2.0 * speed),
    };
    let modes = ModesSettings {
        from: Some(lo),
        to: Some(hi),
        max_hz: None,
        formulation: settings.formulation,
    };
    let analysis = crate::analysis::modes(scene, &modes);
    let failed = match &analysis {
        Ok(a) => format!(
            "{}: the operating point did not converge ({}): no linearisation",
            scene.file, a.termination
        ),
        Err(_) => String::new(),
    };
    let dir = out.join("modes");
    Part::run(
        &scene.file,
        analysis,
        ModesAnalysis::exit_code,
        &failed,
        |a| super::write_modes_files(&dir, scene, a, warnings).map(|_| ()),
    )
}
