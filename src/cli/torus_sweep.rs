//! `hbal sweep` of a scene on several base frequencies ([`hbal::analysis::torus_sweep`]):
//! evenly spaced speeds (`--points`), the points that failed, the peak of every order cut, or
//! the JSON; `--out` writes `points.csv`, `order_cuts.csv`, `order_cuts.svg` and
//! `waterfall.svg` (the lines of one element coordinate over speed, sidebands included).

use super::progress::Progress;
use super::Failure;
use anyhow::Context;
use hbal::analysis::{TorusSweepAnalysis, TorusSweepSettings};
use hbal::report::{line_plot, waterfall_plot, Axis, Series, Slice, Waterfall};
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
    let elements = scene.model.elements();
    let shown = match opts.output {
        None => elements.first().map(|e| e.name().to_string()),
        Some(name) if elements.iter().any(|e| e.name() == name) => Some(name.to_string()),
        Some(name) => {
            let names: Vec<&str> = elements.iter().map(|e| e.name()).collect();
            return Err(anyhow::anyhow!(
                "--output `{name}`: on the torus the order cuts are those of an element coordinate (the scene has: {})",
                names.join(", ")
            )
            .into());
        }
    };
    if let Some(dir) = opts.out {
        let files = [
            "points.csv",
            "order_cuts.csv",
            "order_cuts.svg",
            "waterfall.svg",
        ];
        super::prepare_out(dir, &files.map(String::from))?;
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
        write_files(dir, scene, &a, shown.as_deref())
            .with_context(|| format!("--out: cannot write {}", dir.display()))?;
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

fn write_files(
    dir: &Path,
    scene: &Scene,
    a: &TorusSweepAnalysis,
    shown: Option<&str>,
) -> anyhow::Result<()> {
    let unit = &a.speed_unit;
    let mut w = csv::Writer::from_path(dir.join("points.csv"))?;
    let mut header = vec![
        format!("speed_{unit}"),
        "converged".into(),
        "relative_residual".into(),
        "newton_steps".into(),
    ];
    header.extend(a.bases.iter().map(|b| format!("truncation_{}", b.name)));
    w.write_record(&header)?;
    for p in &a.points {
        let mut row = vec![
            format!("{:e}", p.speed),
            p.converged.to_string(),
            format!("{:e}", p.relative_residual),
            p.iterations.to_string(),
        ];
        row.extend(
            p.estimates
                .iter()
                .map(|e| e.map_or(String::new(), |e| format!("{e:e}"))),
        );
        w.write_record(&row)?;
    }
    w.flush()?;
    let mut w = csv::Writer::from_path(dir.join("order_cuts.csv"))?;
    w.write_record([
        format!("speed_{unit}"),
        "element".into(),
        "line".into(),
        "order".into(),
        "amplitude".into(),
        "converged".into(),
    ])?;
    for c in &a.order_cuts {
        for (p, amp) in a.points.iter().zip(&c.amplitudes) {
            w.write_record([
                format!("{:e}", p.speed),
                c.element.clone(),
                c.label.clone(),
                format!("{:e}", c.order),
                format!("{amp:e}"),
                p.converged.to_string(),
            ])?;
        }
    }
    w.flush()?;
    let Some(name) = shown else { return Ok(()) };
    if a.points.len() < 2 {
        return Ok(());
    }
    let speed_axis = format!("speed ({unit})");
    let series: Vec<Series> = a
        .order_cuts
        .iter()
        .filter(|c| c.element == name)
        .map(|c| {
            let points = a
                .points
                .iter()
                .zip(&c.amplitudes)
                .map(|(p, &x)| (p.speed, x))
                .collect();
            Series::line(
                format!("{} (order {})", c.label, super::speed_text(c.order)),
                points,
            )
        })
        .collect();
    let title = |kind: &str| format!("{kind} of the coordinate of `{name}`: {}", scene.file);
    line_plot(
        &dir.join("order_cuts.svg"),
        &title("Order cuts"),
        &Axis::linear(&speed_axis),
        &Axis::auto("amplitude"),
        &series,
    )
    .unwrap_or_else(super::plot_warning);
    waterfall(dir, scene, a, name, &title("Waterfall"), &speed_axis);
    Ok(())
}

/// `waterfall.svg`: every line of the element's coordinate at every point, at its order; the
/// mesh harmonics (lines of one base) in colour, their sidebands grey.
fn waterfall(
    dir: &Path,
    scene: &Scene,
    a: &TorusSweepAnalysis,
    name: &str,
    title: &str,
    speed_axis: &str,
) {
    let Some(e) = scene.model.elements().iter().find(|e| e.name() == name) else {
        return;
    };
    let slices: Vec<Slice> = a
        .solutions
        .iter()
        .map(|s| {
            let q = s.coordinate_lines(e.weights());
            Slice {
                speed: s.omega / scene.torus.as_ref().map_or(1.0, |p| p.rad_s_per_speed),
                amplitudes: (1..q.len()).map(|j| (s.order(j), q[j].norm())).collect(),
            }
        })
        .collect();
    let highlight: Vec<f64> = a
        .solutions
        .first()
        .map(|s| {
            (1..s.indices.len())
                .filter(|&j| s.indices[j].iter().filter(|&&k| k != 0).count() == 1)
                .map(|j| s.order(j))
                .collect()
        })
        .unwrap_or_default();
    let plot = Waterfall {
        title,
        speed_label: speed_axis,
        unit: "m",
        range_db: 60.0,
        highlight: &highlight,
    };
    waterfall_plot(&dir.join("waterfall.svg"), &plot, &slices).unwrap_or_else(super::plot_warning);
}
