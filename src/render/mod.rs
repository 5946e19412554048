//! Rendering of analysis results into files: the last step of the data flow (scene -> model
//! -> harmonic basis -> residual -> solver -> solution -> analysis result -> **rendering**).
//!
//! Every front end writes the same files from the same typed results: `hbal solve --out DIR`
//! and Python's `solve(..., out=DIR)` call [`write_solve_files`], a sweep
//! [`write_sweep_files`] (a parameter sweep [`write_parameter_sweep_files`]), the natural
//! frequencies [`write_modes_files`], a comparison [`write_compare_files`], and [`report`] runs
//! the solve, the run-up and the natural frequencies and builds one self-contained
//! `report.html` from them. The output directory is checked before any work
//! ([`prepare_out`]). A plot that cannot be drawn (nothing finite to show) is a warning in
//! the returned list: the computation and its CSV files stand.

mod compare_files;
mod modes_files;
mod order_cuts;
mod out_dir;
mod parameter_sweep_files;
mod report;
mod report_html;
mod solve_files;
mod sweep_files;
mod torus_report;
mod torus_solve_files;
mod torus_sweep_files;

pub use compare_files::{compare_files, write_compare_files};
pub use modes_files::write_modes_files;
pub use out_dir::{
    file_name_part, modes_files, prepare_out, prepare_sweep_out, solve_files, sweep_files,
    torus_solve_files, torus_sweep_files,
};
pub use parameter_sweep_files::{parameter_sweep_files, write_parameter_sweep_files};
pub use report::{report, Part, PeriodicParts, Report, ReportParts, ReportSettings};
pub use solve_files::{element_csv, write_solve_files};
pub use sweep_files::write_sweep_files;
pub use torus_solve_files::write_torus_solve_files;
pub use torus_sweep_files::{torus_shown, write_torus_sweep_files};

use crate::error::Error;
use std::path::Path;

/// A speed for titles and text: up to 6 significant digits, no trailing zeros (`2000`,
/// `1.3455`).
///
/// ```
/// assert_eq!(hbal::render::speed_text(2000.0), "2000");
/// assert_eq!(hbal::render::speed_text(1.3455), "1.3455");
/// ```
pub fn speed_text(v: f64) -> String {
    let digits = if v == 0.0 || !v.is_finite() {
        0
    } else {
        (5 - v.abs().log10().floor() as i32).clamp(0, 12) as usize
    };
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Keeps a plot's failure as a warning (`plot: why`).
fn plot_warning(warnings: &mut Vec<String>, result: Result<(), Box<dyn std::error::Error>>) {
    if let Err(e) = result {
        warnings.push(format!("plot: {e}"));
    }
}

/// A failure to write into `dir` (bad input: the directory was checked, something changed).
fn cannot_write(dir: &Path, e: impl std::fmt::Display) -> Error {
    Error::Output(format!("--out: cannot write {}: {e:#}", dir.display()))
}
