//! `out=`: the files of an analysis, as `--out DIR` writes them ([`hbal::render`]). The
//! directory is checked before any work (bad input: `InputError`), the files are written
//! after it with the GIL released, and a plot that cannot be drawn is a Python
//! `RuntimeWarning` (the analysis and its CSV files stand).

use crate::scene::Prepared;
use pyo3::exceptions::PyRuntimeWarning;
use pyo3::prelude::*;
use std::ffi::CString;
use std::path::Path;

/// Checks `dir` (where given) for `files` before any work.
pub fn prepare(
    py: Python<'_>,
    p: &Prepared<'_>,
    dir: Option<&Path>,
    files: &[String],
) -> PyResult<()> {
    match dir {
        Some(d) => hbal::render::prepare_out(d, files).map_err(|e| p.error(py, e)),
        None => Ok(()),
    }
}

/// Runs `write` (the files into `dir`, where given) with the GIL released; its warnings as
/// `RuntimeWarning`s.
pub fn write(
    py: Python<'_>,
    p: &Prepared<'_>,
    dir: Option<&Path>,
    write: impl FnOnce(&Path, &mut Vec<String>) -> hbal::Result<()> + Send,
) -> PyResult<()> {
    let Some(dir) = dir else { return Ok(()) };
    let mut warnings = Vec::new();
    py.detach(|| write(dir, &mut warnings))
        .map_err(|e| p.error(py, e))?;
    warn(py, &warnings)
}

/// Each of `warnings` as a `RuntimeWarning`.
pub fn warn(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    let category = py.get_type::<PyRuntimeWarning>();
    for w in warnings {
        let message = CString::new(w.replace('\0', " ")).unwrap_or_default();
        PyErr::warn(py, &category, &message, 2)?;
    }
    Ok(())
}
