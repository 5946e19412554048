//! A scene built once for the analyses of Python: [`SceneHandle`] holds the library's
//! [`Scene`] and the document it came from (with the registry keys of its Python laws), so
//! that every analysis without overrides reuses the build and one with overrides builds its
//! own from the same document.

use crate::errors::{scene_error, to_py};
use crate::law::{self, FailureSlot, Registered};
use crate::value::{to_python, to_value};
use hbal::scene::{Overrides, Scene};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// A built scene (from `build_scene`).
#[pyclass(frozen, module = "hbal._hbal")]
pub struct SceneHandle {
    pub scene: Scene,
    /// The document as the library reads it (Python laws named by their registry keys).
    pub document: Value,
    pub file: String,
    /// The failures of the scene's Python laws.
    pub slot: Arc<FailureSlot>,
    keys: Vec<String>,
}

impl Drop for SceneHandle {
    fn drop(&mut self) {
        law::unregister(&self.keys);
    }
}

impl SceneHandle {
    /// The scene with `overrides` applied: the built one where there are none, else a new
    /// build of the document.
    pub fn with(&self, overrides: &Overrides) -> hbal::Result<Built<'_>> {
        if *overrides == command_line_defaults() {
            return Ok(Built::Shared(&self.scene));
        }
        let mut scene = Scene::from_value(self.document.clone(), &self.file)?;
        overrides.apply(&mut scene)?;
        Ok(Built::Own(Box::new(scene)))
    }

    /// The first failure of a Python law since the last call, as the exception to raise.
    pub fn law_failure(&self) -> Option<PyErr> {
        self.slot.take()
    }
}

#[pymethods]
impl SceneHandle {
    /// What the scene holds: DOF names, elements, speed unit and speed, harmonics, samples,
    /// whether it has an operating point and is solved on several base frequencies, notes.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let s = &self.scene;
        let info = serde_json::json!({
            "file": s.file,
            "description": s.description,
            "dofs": s.model.dof_names(),
            "elements": s.model.elements().iter().map(|e| e.name()).collect::<Vec<_>>(),
            "speed_unit": s.speed_unit,
            "speed": s.basis.omega() / s.omega_per_speed,
            "fundamental_rad_s": s.basis.omega(),
            "fundamental_order": s.fundamental_order,
            "harmonics": s.basis.harmonics(),
            "samples": s.basis.samples(),
            "operating_point": s.operating_point,
            "torus": s.torus.is_some(),
            "notes": s.notes,
        });
        to_python(py, &info)
    }
}

/// The overrides the command line applies when none is given (`--formulation auto`): the
/// built scene has them, so that an analysis without options reuses it.
fn command_line_defaults() -> Overrides {
    Overrides {
        formulation: hbal::Formulation::Auto,
        ..Overrides::default()
    }
}

/// The handle's scene, or one built with overrides.
pub enum Built<'a> {
    Shared(&'a Scene),
    Own(Box<Scene>),
}

impl std::ops::Deref for Built<'_> {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        match self {
            Built::Shared(s) => s,
            Built::Own(s) => s,
        }
    }
}

static NEXT_BUILD: AtomicU64 = AtomicU64::new(0);

/// Builds the scene of `document` (a dict; files it names are relative to the directory of
/// `file`), with the Python force laws `laws` (a dict of names and functions).
#[pyfunction]
#[pyo3(signature = (document, file, laws=None))]
pub fn build_scene(
    py: Python<'_>,
    document: &Bound<'_, PyAny>,
    file: &str,
    laws: Option<&Bound<'_, PyDict>>,
) -> PyResult<SceneHandle> {
    let mut document = to_value(document, "scene")?;
    let slot = Arc::new(FailureSlot::default());
    let mut keys = Vec::new();
    let build = NEXT_BUILD.fetch_add(1, Ordering::Relaxed);
    if let Some(laws) = laws {
        for (name, callable) in laws.iter() {
            let name: String = name.extract()?;
            if name.contains('#') {
                return Err(crate::errors::InputError::new_err(format!(
                    "laws: the name `{name}` may not contain `#`"
                )));
            }
            let key = format!("{name}#{build}");
            let floats = law::takes_floats(py, &callable);
            law::register(
                key.clone(),
                Registered {
                    callable: callable.unbind(),
                    slot: slot.clone(),
                    floats,
                },
            );
            rename_laws(&mut document, &name, &key);
            keys.push(key);
        }
    }
    // Building calls the laws (their linear part): a law's failure is the error to raise.
    let built = Scene::from_value(document.clone(), file);
    let failed = slot.take();
    let scene = match (built, failed) {
        (Ok(mut scene), None) => {
            command_line_defaults()
                .apply(&mut scene)
                .map_err(|e| crate::errors::to_py(py, e))?;
            scene
        }
        (_, Some(failure)) => {
            law::unregister(&keys);
            return Err(failure);
        }
        (Err(e), None) => {
            law::unregister(&keys);
            return Err(scene_error(py, &unkeyed(e)));
        }
    };
    Ok(SceneHandle {
        scene,
        document,
        file: file.to_string(),
        slot,
        keys,
    })
}

/// Every element `{ type = "python", law = name }` of `document` names `key` instead.
fn rename_laws(document: &mut Value, name: &str, key: &str) {
    let Some(elements) = document.get_mut("elements").and_then(Value::as_array_mut) else {
        return;
    };
    for e in elements {
        let python = e.get("type").and_then(Value::as_str) == Some("python");
        if python && e.get("law").and_then(Value::as_str) == Some(name) {
            e["law"] = Value::String(key.to_string());
        }
    }
}

/// A scene error with registry keys in its message written as the user's names.
fn unkeyed(mut e: hbal::scene::SceneError) -> hbal::scene::SceneError {
    while let Some(at) = e.message.find('#') {
        let end = e.message[at + 1..]
            .find(|c: char| !c.is_ascii_digit())
            .map_or(e.message.len(), |n| at + 1 + n);
        e.message.replace_range(at..end, "");
    }
    e
}

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
    toml::to_string(&value).map_err(|e| {
        crate::errors::InputError::new_err(format!("the scene cannot be written as TOML: {e}"))
    })
}

/// `Error` of the library, for the analyses.
pub fn error(py: Python<'_>, handle: &SceneHandle, e: hbal::Error) -> PyErr {
    handle.law_failure().unwrap_or_else(|| to_py(py, e))
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
        return Err(crate::errors::InputError::new_err(format!(
            "`{path}`: must be a finite number, got {value}"
        )));
    }
    hbal::scene::set_parameter(&mut doc, path, value)
        .map_err(crate::errors::InputError::new_err)?;
    to_python(py, &doc)
}
