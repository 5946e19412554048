//! The files of a solve on several base frequencies (`hbal solve --out DIR` of a torus
//! scene): `lines.csv` (every line of every DOF, element coordinate and force, by its
//! combination of base orders) and `spectrum.svg` (the element coordinates' lines over order).

use super::cannot_write;
use crate::analysis::TorusSolveAnalysis;
use crate::error::Result;
use crate::report::csv_number;
use crate::report::{line_plot, Axis, Series};
use crate::scene::Scene;
use std::path::Path;

/// Writes `lines.csv` and `spectrum.svg` of `a` (a torus solve of `scene`) into `dir`. A
/// plot that cannot be drawn is a warning in `warnings`.
pub fn write_torus_solve_files(
    dir: &Path,
    scene: &Scene,
    a: &TorusSolveAnalysis,
    warnings: &mut Vec<String>,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| cannot_write(dir, e))?;
    write_lines(&dir.join("lines.csv"), a).map_err(|e| cannot_write(dir, e))?;
    plot_spectrum(&dir.join("spectrum.svg"), scene, a, warnings);
    Ok(())
}

/// `lines.csv`: every line of every element coordinate and DOF.
fn write_lines(path: &Path, a: &TorusSolveAnalysis) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    let mut header = vec!["what".to_string(), "name".to_string(), "line".to_string()];
    header.extend(a.bases.iter().map(|b| format!("k_{}", b.name)));
    header.extend(["order", "hz", "amplitude", "phase_deg"].map(String::from));
    w.write_record(&header)?;
    let sol = &a.solution;
    for (what, name, q) in quantities(a) {
        for (j, (k, q)) in sol.indices.iter().zip(&q).enumerate() {
            let order = sol.order(j);
            let mut row = vec![
                what.to_string(),
                name.clone(),
                crate::analysis::line_label(&sol.bases, k),
            ];
            row.extend(k.iter().map(|k| k.to_string()));
            row.push(csv_number(order));
            row.push(csv_number(order * sol.omega / std::f64::consts::TAU));
            row.push(csv_number(q.norm()));
            row.push(csv_number(q.arg().to_degrees()));
            w.write_record(&row)?;
        }
    }
    Ok(w.flush()?)
}

/// Every DOF's and element coordinate's lines, line by line.
fn quantities(
    a: &TorusSolveAnalysis,
) -> Vec<(&'static str, String, Vec<crate::num_complex::Complex64>)> {
    let sol = &a.solution;
    let n = sol.n_dofs();
    let line = |j: usize, i: usize| {
        let (re, im) = sol.harmonics[j * n + i];
        crate::num_complex::Complex64::new(re, im)
    };
    let mut out: Vec<_> = (0..n)
        .map(|i| {
            (
                "dof",
                sol.dofs[i].clone(),
                (0..sol.indices.len()).map(|j| line(j, i)).collect(),
            )
        })
        .collect();
    out.extend(
        a.element_lines
            .iter()
            .map(|(name, q)| ("element", name.clone(), q.clone())),
    );
    out.extend(
        a.force_lines
            .iter()
            .map(|(name, q)| ("force", name.clone(), q.clone())),
    );
    out
}

/// `spectrum.svg`: every element coordinate's lines over their order (log amplitude).
fn plot_spectrum(path: &Path, scene: &Scene, a: &TorusSolveAnalysis, warnings: &mut Vec<String>) {
    let series: Vec<Series> = a
        .element_lines
        .iter()
        .map(|(name, q)| {
            let mut points: Vec<(f64, f64)> = (1..q.len())
                .map(|j| (a.solution.order(j), q[j].norm()))
                .filter(|p| p.1 > 0.0)
                .collect();
            points.sort_by(|x, y| x.0.total_cmp(&y.0));
            Series::markers(name.clone(), points)
        })
        .collect();
    if series.iter().all(|s| s.points.is_empty()) {
        return;
    }
    let title = format!(
        "Lines of the element coordinates at {} {}: {}",
        super::speed_text(a.speed),
        a.speed_unit,
        scene.file
    );
    let plot = line_plot(
        path,
        &title,
        &Axis::linear(format!("order of the speed ({})", a.speed_unit)),
        &Axis::log("amplitude"),
        &series,
    );
    super::plot_warning(warnings, plot);
}
