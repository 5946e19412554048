//! `hbal modes`: runs the library's modes analysis ([`hbal::analysis::modes`]: natural
//! frequencies and mode shapes about the periodic solution, with the one- and two-tooth
//! bounds of time-varying meshes, the excitation orders and the critical speeds) and renders
//! it as a table or JSON; a Campbell diagram and `modes.csv` with `--out`.

use super::{load, Failure, SolverArgs};
use anyhow::Context;
use hbal::analysis::{ModesAnalysis, ModesSettings};
use hbal::report::{line_plot, Axis, NaturalFrequencies, Series};
use hbal::scene::Scene;
use std::f64::consts::TAU;
use std::path::Path;

/// Options of `hbal modes`.
pub(crate) struct ModesOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: Option<f64>,
    pub(crate) max_hz: Option<f64>,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
}

pub(crate) fn modes(path: &Path, args: &SolverArgs, opts: ModesOptions) -> Result<u8, Failure> {
    let as_json = opts.json;
    let scene = load(path, args)?;
    if let Some(dir) = opts.out {
        super::prepare_out(dir, &super::modes_files())?;
    }
    let settings = ModesSettings {
        from: opts.from,
        to: opts.to,
        max_hz: opts.max_hz,
        formulation: args.formulation,
    };
    let a = hbal::analysis::modes(&scene, &settings).map_err(|e| super::failure(e, &scene.file))?;
    let Some(nf) = &a.natural else {
        if opts.json {
            // The document still comes, marked: what failed instead of the modes (the
            // report says it in its page instead).
            say!("{}", a.to_json());
        }
        return Err(Failure {
            code: 1,
            error: anyhow::anyhow!(
                "{}: the operating point did not converge ({}): no linearisation",
                a.file,
                a.termination
            ),
        });
    };
    if as_json {
        say!("{}", a.to_json());
    } else {
        table(&a, nf);
    }
    if let Some(dir) = opts.out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--out: cannot create {}", dir.display()))?;
        write_outputs(dir, &scene, nf, &a.orders, a.range, a.per_unit)
            .with_context(|| format!("--out: cannot write into {}", dir.display()))?;
        if !as_json {
            say!("  wrote modes.csv, campbell.svg to {}", dir.display());
        }
    }
    Ok(0)
}

/// The table of modes, the excitation orders and the critical speeds.
fn table(a: &ModesAnalysis, nf: &NaturalFrequencies) {
    let limit = if a.max_hz.is_finite() {
        format!("{} Hz", a.max_hz)
    } else {
        "the highest".into()
    };
    let at = if a.linear {
        "a linear model (no operating point needed)".to_string()
    } else {
        format!(
            "linearised on the orbit at {} {}",
            a.operating_speed.unwrap_or(f64::NAN),
            a.unit
        )
    };
    say!(
        "{}: {} modes up to {limit} ({} rigid), {at}",
        a.file,
        nf.mean.len(),
        nf.rigid
    );
    say!("  mode   mean Hz    one-tooth Hz   two-tooth Hz   largest DOF");
    for (i, f) in nf.mean.iter().enumerate() {
        let top = nf.shapes.column(i).iamax();
        say!(
            "  {:>4}  {:>11.4}  {:>11.4}    {:>11.4}     {}",
            i + 1,
            f,
            nf.lower.get(i).copied().unwrap_or(f64::NAN),
            nf.upper.get(i).copied().unwrap_or(f64::NAN),
            a.dofs[top]
        );
    }
    let list: Vec<String> = a.orders.iter().map(|o| format!("{o}")).collect();
    say!("  excitation orders: {}", list.join(", "));
    for c in &a.critical {
        say!(
            "  critical speed {:.2} {}: order {} meets mode {}",
            c.speed,
            a.unit,
            c.order,
            c.mode
        );
    }
}

/// `modes.csv` (frequencies and shapes) and `campbell.svg`.
pub(crate) fn write_outputs(
    dir: &Path,
    scene: &Scene,
    nf: &NaturalFrequencies,
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
