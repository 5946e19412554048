//! The files of a sweep on several base frequencies (`hbal sweep --out DIR` of a torus scene):
//! `points.csv` (every point's convergence and truncation estimates), `order_cuts.csv`,
//! `order_cuts.svg` and `waterfall.svg` (the lines of one element coordinate over speed,
//! sidebands included).

use super::{cannot_write, speed_text};
use crate::analysis::TorusSweepAnalysis;
use crate::error::{Error, Result};
use crate::report::csv_number;
use crate::report::{line_plot, waterfall_plot, Axis, Series, Slice, Waterfall};
use crate::scene::Scene;
use std::path::Path;

/// The element whose order cuts and waterfall a torus sweep plots: `output` (which must name
/// an element: on the torus the order cuts are those of element coordinates), by default the
/// first element; `None` for a scene without elements.
pub fn torus_shown(scene: &Scene, output: Option<&str>) -> Result<Option<String>> {
    let elements = scene.model.elements();
    match output {
        None => Ok(elements.first().map(|e| e.name().to_string())),
        Some(name) if elements.iter().any(|e| e.name() == name) => Ok(Some(name.to_string())),
        Some(name) => {
            let names: Vec<&str> = elements.iter().map(|e| e.name()).collect();
            Err(Error::InvalidOptions {
                option: format!("--output `{name}`:"),
                reason: format!(
                    "on the torus the order cuts are those of an element coordinate (the scene has: {})",
                    names.join(", ")
                ),
            })
        }
    }
}

/// Writes the files of `a` (a torus sweep of `scene`) into `dir`, the plots of the element
/// `shown` ([`torus_shown`]). A plot that cannot be drawn is a warning in `warnings`.
pub fn write_torus_sweep_files(
    dir: &Path,
    scene: &Scene,
    a: &TorusSweepAnalysis,
    shown: Option<&str>,
    warnings: &mut Vec<String>,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| cannot_write(dir, e))?;
    write_files(dir, scene, a, shown, warnings).map_err(|e| cannot_write(dir, e))
}

fn write_files(
    dir: &Path,
    scene: &Scene,
    a: &TorusSweepAnalysis,
    shown: Option<&str>,
    warnings: &mut Vec<String>,
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
            csv_number(p.speed),
            p.converged.to_string(),
            csv_number(p.relative_residual),
            p.iterations.to_string(),
        ];
        row.extend(
            p.estimates
                .iter()
                .map(|e| e.map_or(String::new(), csv_number)),
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
                csv_number(p.speed),
                c.element.clone(),
                c.label.clone(),
                csv_number(c.order),
                csv_number(*amp),
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
                format!("{} (order {})", c.label, speed_text(c.order)),
                points,
            )
        })
        .collect();
    let title = |kind: &str| format!("{kind} of the coordinate of `{name}`: {}", scene.file);
    let plot = line_plot(
        &dir.join("order_cuts.svg"),
        &title("Order cuts"),
        &Axis::linear(&speed_axis),
        &Axis::auto("amplitude"),
        &series,
    );
    super::plot_warning(warnings, plot);
    let plot = waterfall(dir, scene, a, name, &title("Waterfall"), &speed_axis);
    super::plot_warning(warnings, plot);
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
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let Some(e) = scene.model.elements().iter().find(|e| e.name() == name) else {
        return Ok(());
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
    waterfall_plot(&dir.join("waterfall.svg"), &plot, &slices)
}
