//! Scene documents between Python and the library: parsing text and files, writing TOML,
//! setting one number at a field path.

use crate::errors::{scene_error, InputError};
use crate::value::{to_python, to_value};
use hbal::scene::Scene;
use pyo3::prelude::*;

/// Parses scene text (TOML, or JSON where `file` ends in `.json`) into its document, with
/// the file's syntax checks.
#[pyfunction]
pub fn parse_scene<'py>(py: Python<'py>, text: &str, file: &str) -> PyResult<Bound<'py, PyAny>> {
    let value = Scene::parse_value(text, file).map_err(|e| scene_error(py, &e))?;
    to_python(py, &value)
}

/// Reads and parses a scene file into its document.
#[pyfunction]
pub fn read_scene<'py>(py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyAny>> {
    let p = std::path::Path::new(path);
    let text = hbal::scene::bounded_read::read_text(p).map_err(|e| {
        let err = hbal::scene::SceneError {
            file: path.to_string(),
            position: None,
            path: None,
            message: format!("cannot read the file: {e}"),
        };
        scene_error(py, &err)
    })?;
    parse_scene(py, &text, path)
}

/// The document as TOML text.
#[pyfunction]
pub fn document_to_toml(document: &Bound<'_, PyAny>) -> PyResult<String> {
    let value = to_value(document, "scene")?;
    toml::to_string(&value)
        .map_err(|e| InputError::new_err(format!("the scene cannot be written as TOML: {e}")))
}

/// The document with the number at `path` (e.g. `elements[0].k`, `fundamental.rpm`) set to
/// `value` (the library's `set_parameter`, as a parameter sweep and a study's variant use it).
#[pyfunction]
pub fn set_parameter<'py>(
    py: Python<'py>,
    document: &Bound<'py, PyAny>,
    path: &str,
    value: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let mut doc = to_value(document, "scene")?;
    if !value.is_finite() {
        return Err(InputError::new_err(format!(
            "`{path}`: must be a finite number, got {value}"
        )));
    }
    hbal::scene::set_parameter(&mut doc, path, value).map_err(InputError::new_err)?;
    to_python(py, &doc)
}
