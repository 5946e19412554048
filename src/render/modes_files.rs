//! The files of the natural frequencies (`hbal modes --out DIR`): `modes.csv` (every mode's
//! mean frequency, its one- and two-tooth bounds and its shape) and the Campbell diagram
//! `campbell.svg` (natural frequencies, excitation order lines and critical speeds over the
//! speed range).

use super::cannot_write;
use crate::analysis::ModesAnalysis;
use crate::error::Result;
use crate::report::csv_number;
use crate::report::{line_plot, Axis, NaturalFrequencies, Series};
use crate::scene::Scene;
use std::f64::consts::TAU;
use std::path::Path;

/// Writes `modes.csv` and `campbell.svg` of `a` (the natural frequencies of `scene`) into
/// `dir` and returns the names written; nothing where the operating point did not converge
/// (no linearisation). A plot that cannot be drawn is a warning in `warnings`.
pub fn write_modes_files(
    dir: &Path,
    scene: &Scene,
    a: &ModesAnalysis,
    warnings: &mut Vec<String>,
) -> Result<Vec<String>> {
    let Some(nf) = &a.natural else {
        return Ok(Vec::new());
    };
    let before = warnings.len();
    write_outputs(dir, scene, a, nf, warnings).map_err(|e| cannot_write(dir, e))?;
    let mut written = vec!["modes.csv".to_string()];
    if warnings.len() == before {
        written.push("campbell.svg".into());
    }
    Ok(written)
}

/// `modes.csv` (frequencies and shapes) and `campbell.svg`.
fn write_outputs(
    dir: &Path,
    scene: &Scene,
    a: &ModesAnalysis,
    nf: &NaturalFrequencies,
    warnings: &mut Vec<String>,
) -> anyhow::Result<()> {
    let (orders, (from, to), per_unit) = (&a.orders, a.range, a.per_unit);
    std::fs::create_dir_all(dir)?;
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
            csv_number(*f),
            csv_number(nf.lower.get(i).copied().unwrap_or(f64::NAN)),
            csv_number(nf.upper.get(i).copied().unwrap_or(f64::NAN)),
        ];
        row.extend(nf.shapes.column(i).iter().map(|v| csv_number(*v)));
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
    let plot = line_plot(
        &dir.join("campbell.svg"),
        &format!("Campbell diagram: {}", scene.file),
        &Axis::linear(format!("speed ({})", scene.speed_unit)),
        &Axis::linear("frequency (Hz)"),
        &series,
    );
    super::plot_warning(warnings, plot);
    Ok(())
}
