//! The file of a comparison (`hbal compare --out DIR`): `residual_histories.svg`, every
//! method's relative residual over its iterations.

use super::cannot_write;
use crate::analysis::CompareAnalysis;
use crate::error::Result;
use crate::report::{line_plot, Axis, Series};
use std::path::Path;

/// The files a comparison writes.
pub fn compare_files() -> Vec<String> {
    vec!["residual_histories.svg".to_string()]
}

/// Writes `residual_histories.svg` of `a` into `dir`. A plot that cannot be drawn is a
/// warning in `warnings`.
pub fn write_compare_files(
    dir: &Path,
    a: &CompareAnalysis,
    warnings: &mut Vec<String>,
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| cannot_write(dir, e))?;
    let histories: Vec<Series> = a
        .methods
        .iter()
        .map(|m| {
            let points = m.solution.history.iter().enumerate();
            Series::line(&m.method, points.map(|(i, r)| (i as f64, *r)).collect())
        })
        .collect();
    let (x, y) = (Axis::linear("iteration"), Axis::log("relative residual"));
    let plot = line_plot(
        &dir.join("residual_histories.svg"),
        "Residual histories",
        &x,
        &y,
        &histories,
    );
    super::plot_warning(warnings, plot);
    Ok(())
}
