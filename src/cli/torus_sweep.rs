//! `hbal sweep` of a scene on several base frequencies ([`hbal::analysis::torus_sweep`]):
//! evenly spaced speeds (`--points`), the points that failed, the peak of every order cut, or
//! the JSON; `--out` writes `points.csv`, `order_cuts.csv`, `order_cuts.svg` and
//! `waterfall.svg` (the lines of one element coordinate over speed, sidebands included).

use super::progress::Progress;
use super::Failure;
use anyhow::Context;
use hbal::analysis::{TorusSweepAnalysis, TorusSweepSettings};
use hbal::scene::Scene;
use std::path::Path;

/// The options of a torus sweep.
pub(crate) struct TorusSweepOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: f64,
    pub(crate) points: usize,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
    /// The element whose order cuts and waterfall are plotted (default: the first).
    pub(crate) output: Option<&'a str>,
}

/// Sweeps, prints and writes; the exit code of the analysis.
pub(crate) fn sweep(scene: &Scene, opts: TorusSweepOptions) -> Result<u8, Failure> {
    let (json, out) = (opts.json, opts.out);
    let a = run(scene, opts)?;
    if json {
        say!(
            "{}",
            serde_json::to_string(&a).context("JSON of the sweep")?
        );
    } else {
        print(scene, &a);
        if let Some(dir) = out {
            say!(
                "  wrote points.csv, order_cuts.csv, order_cuts.svg, waterfall.svg to {}",
                dir.display()
            );
        }
    }
    if let Some(why) = &a.caps_stopped {
        eprintln!("error: {}: automatic caps: {why}", scene.file);
    }
    if a.failures() > 0 {
        eprintln!(
            "error: {}: {} of {} points did not converge or could not be set up (marked in points.csv and the JSON)",
            scene.file,
            a.failures(),
            a.points.len() + a.skipped.len()
        );
    }
    Ok(a.exit_code())
}

/// Checks the options, sweeps (a progress bar unless `json`) and writes the files of `out`.
pub(crate) fn run(scene: &Scene, opts: TorusSweepOptions) -> Result<TorusSweepAnalysis, Failure> {
    let shown = hbal::render::torus_shown(scene, opts.output)
        .map_err(|e| super::failure(e, &scene.file))?;
    if let Some(dir) = opts.out {
        hbal::render::prepare_out(dir, &hbal::render::torus_sweep_files())
            .map_err(|e| super::failure(e, &scene.file))?;
    }
    let settings = TorusSweepSettings {
        from: opts.from,
        to: opts.to,
        points: opts.points,
    };
    let progress = Progress::new("sweep", opts.json);
    let a = hbal::analysis::torus_sweep(scene, &settings, &mut &progress)
        .map_err(|e| super::failure(e, &scene.file))?;
    progress.finish();
    if let Some(dir) = opts.out {
        let mut warnings = Vec::new();
        hbal::render::write_torus_sweep_files(dir, scene, &a, shown.as_deref(), &mut warnings)
            .map_err(|e| super::failure(e, &scene.file))?;
        super::print_warnings(&warnings);
    }
    Ok(a)
}

fn print(scene: &Scene, a: &TorusSweepAnalysis) {
    let (first, last) = (a.points.first(), a.points.last());
    say!(
        "{}: {} points from {} to {} {} on several base frequencies ({})",
        scene.file,
        a.points.len(),
        first.map_or("-".into(), |p| super::speed_text(p.speed)),
        last.map_or("-".into(), |p| super::speed_text(p.speed)),
        a.speed_unit,
        a.why
    );
    for b in &a.bases {
        say!(
            "  base {:<10} order {:>9}, cap {}, grid {}, largest truncation estimate {}",
            b.name,
            super::speed_text(b.order),
            b.cap,
            b.samples,
            b.estimate.map_or("-".into(), |e| format!("{e:.1e}"))
        );
    }
    say!("  {} lines per point", a.lines);
    for p in a.points.iter().filter(|p| !p.converged) {
        say!(
            "  NOT CONVERGED at {} {}: relative residual {:.1e}",
            super::speed_text(p.speed),
            a.speed_unit,
            p.relative_residual
        );
    }
    for (s, why) in &a.skipped {
        say!(
            "  skipped {} {}: {why}",
            super::speed_text(*s),
            a.speed_unit
        );
    }
    let hbal::torus::TorusStability::NotComputed { reason } = &a.stability;
    say!("  stability: {reason}");
    say!("  element      line                         order        peak  at speed");
    for c in &a.order_cuts {
        say!(
            "  {:<12} {:<26} {:>9} {:>11.4e}  {}",
            c.element,
            c.label,
            super::speed_text(c.order),
            c.peak.0,
            super::speed_text(c.peak.1)
        );
    }
}
