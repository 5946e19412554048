//! `hbal modes`: natural frequencies and mode shapes of a scene linearised about its periodic
//! solution (with the one- and two-tooth bounds of time-varying meshes), the excitation orders
//! and the critical speeds where they cross; a Campbell diagram and `modes.csv` with `--out`.

use super::{load, Failure, SolverArgs};
use anyhow::Context;
use hbal::report::{line_plot, natural_frequencies, Axis, Series};
use hbal::scene::Scene;
use hbal::HarmonicBalance;
use serde_json::json;
use std::f64::consts::TAU;
use std::path::Path;

/// Options of `hbal modes`.
pub(crate) struct ModesOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: Option<f64>,
    pub(crate) max_hz: Option<f64>,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
    /// Keep the JSON document here instead of printing anything (for `hbal report`).
    pub(crate) capture: super::Capture<'a>,
}

pub(crate) fn modes(path: &Path, args: &SolverArgs, opts: ModesOptions) -> Result<u8, Failure> {
    let as_json = opts.json || opts.capture.is_some();
    let scene = load(path, args)?;
    if let Some(dir) = opts.out {
        super::prepare_out(dir)?;
    }
    let speed = scene.basis.omega() / scene.omega_per_speed;
    let (from, to) = (opts.from.unwrap_or(0.0), opts.to.unwrap_or(2.0 * speed));
    hbal::analysis::check_speed(&scene, "--from", from, true)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    hbal::analysis::check_speed(&scene, "--to", to, false).map_err(|e| anyhow::anyhow!("{e}"))?;
    if to <= from {
        return Err(anyhow::anyhow!(
            "--from {from} --to {to}: need 0 <= from < to (in {})",
            scene.speed_unit
        )
        .into());
    }
    let max_hz = match opts.max_hz {
        Some(f) if !(f.is_finite() && f > 0.0) => {
            return Err(anyhow::anyhow!("--max-hz must be finite and > 0, got {f}").into())
        }
        Some(f) => f,
        None if scene.model.n_dofs() <= 300 => f64::INFINITY,
        None => 5000.0,
    };
    // The operating point: the periodic solution at the scene's speed.
    let hb = HarmonicBalance::with_formulation(&scene.model, scene.basis, args.formulation)
        .with_context(|| scene.file.clone())?;
    let sol = scene
        .method
        .solve(&hb, None, &mut hb.workspace())
        .map_err(|e| super::failure(e, &scene.file))?;
    if !sol.is_converged() {
        if opts.json && opts.capture.is_none() {
            // The document still comes, marked: what failed instead of the modes (the
            // report says it in its page instead).
            super::emit(
                json!({
                    "scene": scene.file,
                    "unit": scene.speed_unit,
                    "operating_speed": speed,
                    "converged": false,
                    "termination": sol.termination.to_string(),
                    "error": "the operating point did not converge: no linearisation",
                    "modes": [],
                    "critical_speeds": [],
                }),
                opts.capture,
            );
        }
        return Err(Failure {
            code: 1,
            error: anyhow::anyhow!(
                "{}: the operating point did not converge ({}): no linearisation",
                scene.file,
                sol.termination
            ),
        });
    }
    let nf = natural_frequencies(&scene.model, &sol, max_hz)
        .map_err(|e| super::failure(e, &scene.file))?;
    let orders: Vec<f64> = super::excitation_orders(&scene, &scene.basis)
        .into_iter()
        .map(|(o, _)| o)
        .collect();
    // rad/s of the reference shaft per unit of speed.
    let per_unit = scene.omega_per_speed / scene.fundamental_order;
    let critical: Vec<(f64, usize, f64)> = orders
        .iter()
        .flat_map(|&o| {
            nf.mean
                .iter()
                .enumerate()
                .filter(|(_, f)| **f > 0.0)
                .map(move |(i, &f)| (o, i, TAU * f / (o * per_unit)))
        })
        .filter(|&(_, _, s)| s >= from && s <= to)
        .collect();
    let unit = scene.speed_unit;
    if as_json {
        let doc = json!({
            "scene": scene.file,
            "unit": unit,
            "operating_speed": speed,
            "converged": true,
            "rigid_modes": nf.rigid,
            "modes": nf.mean.iter().enumerate().map(|(i, f)| json!({
                "mean_hz": f,
                "lower_hz": nf.lower.get(i),
                "upper_hz": nf.upper.get(i),
                "shape": nf.shapes.column(i).iter().collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "dofs": scene.model.dof_names(),
            "orders": orders,
            "critical_speeds": critical.iter().map(|(o, i, s)| json!({
                "order": o, "mode": i + 1, "speed": s,
            })).collect::<Vec<_>>(),
        });
        super::emit(doc, opts.capture);
    } else {
        say!(
            "{}: {} modes up to {} ({} rigid), linearised on the orbit at {speed} {unit}",
            scene.file,
            nf.mean.len(),
            if max_hz.is_finite() {
                format!("{max_hz} Hz")
            } else {
                "the highest".into()
            },
            nf.rigid
        );
        say!("  mode   mean Hz    one-tooth Hz   two-tooth Hz   largest DOF");
        for (i, f) in nf.mean.iter().enumerate() {
            let shape = nf.shapes.column(i);
            let top = shape.iamax();
            say!(
                "  {:>4}  {:>11.4}  {:>11.4}    {:>11.4}     {}",
                i + 1,
                f,
                nf.lower.get(i).copied().unwrap_or(f64::NAN),
                nf.upper.get(i).copied().unwrap_or(f64::NAN),
                scene.model.dof_names()[top]
            );
        }
        let list: Vec<String> = orders.iter().map(|o| format!("{o}")).collect();
        say!("  excitation orders: {}", list.join(", "));
        for (o, i, s) in &critical {
            say!(
                "  critical speed {s:.2} {unit}: order {o} meets mode {}",
                i + 1
            );
        }
    }
    if let Some(dir) = opts.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--out: cannot create {}", dir.display()))?;
        write_outputs(dir, &scene, &nf, &orders, (from, to), per_unit)?;
        if !as_json {
            say!("  wrote modes.csv, campbell.svg to {}", dir.display());
        }
    }
    Ok(0)
}

/// `modes.csv` (frequencies and shapes) and `campbell.svg`.
fn write_outputs(
    dir: &Path,
    scene: &Scene,
    nf: &hbal::report::NaturalFrequencies,
    orders: &[f64],
    (from, to): (f64, f64),
    per_unit: f64,
) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(dir.join("modes.csv"))?;
    let mut header = vec![
        "mode".to_string(),
        "mean_hz".into(),
        "lower_hz".into(),
        "upper_hz".into(),
    ];
    header.extend(scene.model.dof_names().iter().cloned());
    w.write_record(&header)?;
    for (i, f) in nf.mean.iter().enumerate() {
        let mut row = vec![
            (i + 1).to_string(),
            format!("{f:e}"),
            format!("{:e}", nf.lower.get(i).copied().unwrap_or(f64::NAN)),
            format!("{:e}", nf.upper.get(i).copied().unwrap_or(f64::NAN)),
        ];
        row.extend(nf.shapes.column(i).iter().map(|v| format!("{v:e}")));
        w.write_record(&row)?;
    }
    w.flush()?;
    // The diagram up to the highest order line's frequency at `to` (and at least the lowest
    // elastic mode).
    let top_order = orders.iter().cloned().fold(0.0, f64::max);
    let f_top = (top_order * to * per_unit / TAU).max(nf.mean.iter().cloned().fold(0.0, f64::min));
    // Natural frequencies black (bounds dashed: one-tooth red, two-tooth blue), one legend
    // entry each; order lines in the other colours; the critical speeds as markers.
    let mut series = Vec::new();
    let (mut first_mode, mut first_bound) = (true, [true, true]);
    let shown = nf
        .mean
        .iter()
        .enumerate()
        .filter(|(_, f)| **f > 0.0 && **f <= 1.2 * f_top);
    for (i, f) in shown {
        let label = if std::mem::take(&mut first_mode) {
            "natural frequency"
        } else {
            ""
        };
        series.push(Series::line(label, vec![(from, *f), (to, *f)]).with_color(0));
        for (j, b) in [&nf.lower, &nf.upper].iter().enumerate() {
            if let Some(&fb) = b.get(i) {
                if (fb - f).abs() > 1e-9 * f {
                    let l = if std::mem::take(&mut first_bound[j]) {
                        ["one-tooth bound", "two-tooth bound"][j]
                    } else {
                        ""
                    };
                    series.push(Series::dashed(l, vec![(from, fb), (to, fb)]).with_color(1 + j));
                }
            }
        }
    }
    for (k, o) in orders.iter().enumerate() {
        let f = |s: f64| o * s * per_unit / TAU;
        series.push(
            Series::line(format!("order {o}"), vec![(from, f(from)), (to, f(to))])
                .with_color(3 + k % 7),
        );
    }
    let crossings: Vec<(f64, f64)> = orders
        .iter()
        .flat_map(|&o| {
            nf.mean
                .iter()
                .filter(|f| **f > 0.0)
                .map(move |&f| (TAU * f / (o * per_unit), f))
        })
        .filter(|&(s, _)| s >= from && s <= to)
        .collect();
    if !crossings.is_empty() {
        series.push(Series::markers("critical speed", crossings).with_color(1));
    }
    line_plot(
        &dir.join("campbell.svg"),
        &format!("Campbell diagram: {}", scene.file),
        &Axis::linear(format!("speed ({})", scene.speed_unit)),
        &Axis::linear("frequency (Hz)"),
        &series,
    )
    .map_err(|e| anyhow::anyhow!("plot: {e}"))
}
