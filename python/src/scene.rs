//! A scene built once for the analyses of Python: [`SceneHandle`] holds the library's
//! [`Scene`] and the document it came from (with the registry keys of its Python laws).
//! An analysis without overrides of a scene without Python laws reuses the build; any other
//! builds its own copy from the document ([`SceneHandle::prepare`]): with overrides, or with
//! Python laws, whose failures then go to that analysis alone.

use crate::errors::{scene_error, to_py, InputError};
use crate::law::registry::{self, FailureSlot, Registered, SlotScope, KEY_MARK};
use crate::value::{to_python, to_value};
use hbal::scene::{Overrides, Scene};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
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
    /// The failures of the scene's own build and of `check`.
    pub slot: Arc<FailureSlot>,
    keys: Vec<String>,
}

impl Drop for SceneHandle {
    fn drop(&mut self) {
        registry::unregister(&self.keys);
    }
}

/// The scene an analysis runs on, and where its laws' failures go while it lives.
pub struct Prepared<'a> {
    pub scene: Built<'a>,
    pub slot: Arc<FailureSlot>,
    _scope: Option<SlotScope>,
    _depth: Nesting,
}

/// How many analyses run nested on this thread (a law that runs an analysis).
struct Nesting;

/// The most analyses nested on one thread: each holds a solver's stack, and a law that runs
/// an analysis of its own scene without end would overflow it.
const MAX_NESTING: usize = 8;

thread_local! {
    static NESTED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

impl Nesting {
    fn enter() -> PyResult<Self> {
        let depth = NESTED.with(|n| n.get());
        if depth >= MAX_NESTING {
            return Err(InputError::new_err(format!(
                "analyses nested more than {MAX_NESTING} deep: a Python law runs an analysis that calls the law again"
            )));
        }
        NESTED.with(|n| n.set(depth + 1));
        Ok(Nesting)
    }
}

impl Drop for Nesting {
    fn drop(&mut self) {
        NESTED.with(|n| n.set(n.get().saturating_sub(1)));
    }
}

impl Prepared<'_> {
    /// The error to raise for `e`: a law's failure first.
    pub fn error(&self, py: Python<'_>, e: hbal::Error) -> PyErr {
        self.slot.take().unwrap_or_else(|| to_py(py, e))
    }
}

impl SceneHandle {
    /// The scene of one analysis with `overrides`: the built one for a scene without Python
    /// laws and no overrides, else a new build (inside the analysis's failure scope, which
    /// lasts as long as the returned value: a parameter sweep's builds report there too).
    pub fn prepare(&self, py: Python<'_>, overrides: &Overrides) -> PyResult<Prepared<'_>> {
        let depth = Nesting::enter()?;
        if self.keys.is_empty() && *overrides == command_line_defaults() {
            let slot = Arc::new(FailureSlot::default());
            let scene = Built::Shared(&self.scene);
            return Ok(Prepared {
                scene,
                slot,
                _scope: None,
                _depth: depth,
            });
        }
        let slot = Arc::new(FailureSlot::default());
        let scope = (!self.keys.is_empty()).then(|| SlotScope::enter(slot.clone()));
        let built = Scene::from_value(self.document.clone(), &self.file)
            .map_err(hbal::Error::from)
            .and_then(|mut scene| overrides.apply(&mut scene).map(|_| scene));
        let mut prepared = Prepared {
            scene: Built::Shared(&self.scene),
            slot,
            _scope: scope,
            _depth: depth,
        };
        match built {
            Ok(scene) => prepared.scene = Built::Own(Box::new(scene)),
            Err(e) => return Err(prepared.error(py, e)),
        }
        if let Some(e) = prepared.slot.take() {
            return Err(e);
        }
        Ok(prepared)
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
            // u = Σ w_i q_i of every element: its coordinate from the DOFs' harmonics.
            "element_weights": s.model.elements().iter()
                .map(|e| (e.name().to_string(), serde_json::json!(e.weights())))
                .collect::<serde_json::Map<_, _>>(),
        });
        to_python(py, &info)
    }
}

/// The overrides the command line applies when none is given (`--formulation auto`): the
/// built scene has them, so that an analysis without options reuses it.
pub fn command_line_defaults() -> Overrides {
    Overrides {
        formulation: hbal::Formulation::Auto,
        ..Overrides::default()
    }
}

/// The handle's scene, or one built for an analysis.
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
    refuse_keys(&document)?;
    let mut named = Vec::new();
    for (name, callable) in laws
        .map(|l| l.iter().collect::<Vec<_>>())
        .unwrap_or_default()
    {
        let name = name
            .cast::<PyString>()
            .map_err(|_| InputError::new_err("laws: the names must be strings"))?
            .to_string();
        if name.contains('#') {
            return Err(InputError::new_err(format!(
                "laws: the name `{name}` may not contain `#`"
            )));
        }
        named.push((name, callable));
    }
    let slot = Arc::new(FailureSlot::default());
    let build = NEXT_BUILD.fetch_add(1, Ordering::Relaxed);
    let mut keys = Vec::new();
    for (name, callable) in named {
        let key = format!("{name}{KEY_MARK}{build}");
        let floats = match crate::law::returned::takes_floats(py, &callable) {
            Ok(floats) => floats,
            Err(interrupted) => {
                registry::unregister(&keys);
                return Err(interrupted);
            }
        };
        let callable = callable.unbind();
        let law = Registered {
            callable,
            slot: slot.clone(),
            floats,
        };
        registry::register(key.clone(), law);
        rename_laws(&mut document, &name, &key);
        keys.push(key);
    }
    // Building calls the laws (their linear part): a law's failure is the error to raise. The
    // build has its own failure scope (it may happen inside another analysis's law).
    let scope = SlotScope::enter(slot.clone());
    let built = Scene::from_value(document.clone(), file);
    drop(scope);
    let failed = slot.take();
    let scene = match (built, failed) {
        (Ok(mut scene), None) => match command_line_defaults().apply(&mut scene) {
            Ok(()) => scene,
            Err(e) => {
                registry::unregister(&keys);
                return Err(to_py(py, e));
            }
        },
        (_, Some(failure)) => {
            registry::unregister(&keys);
            return Err(failure);
        }
        (Err(e), None) => {
            registry::unregister(&keys);
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

/// Python elements of a document name laws by the user's names: a `#` there (the registry
/// keys' mark) is refused, so that a document cannot reach another scene's law.
fn refuse_keys(document: &Value) -> PyResult<()> {
    let elements = document.get("elements").and_then(Value::as_array);
    for (i, e) in elements.into_iter().flatten().enumerate() {
        let python = e.get("type").and_then(Value::as_str) == Some("python");
        if let Some(law) = e.get("law").and_then(Value::as_str).filter(|_| python) {
            if law.contains('#') {
                return Err(InputError::new_err(format!(
                    "scene: elements[{i}].law: `{law}` may not contain `#`"
                )));
            }
        }
    }
    Ok(())
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
    let mut from = 0;
    while let Some(at) = e.message[from..].find(KEY_MARK).map(|a| a + from) {
        let digits = at + KEY_MARK.len();
        let end = e.message[digits..]
            .find(|c: char| !c.is_ascii_digit())
            .map_or(e.message.len(), |n| digits + n);
        if end > digits {
            e.message.replace_range(at..end, "");
        } else {
            from = digits;
        }
    }
    e
}
