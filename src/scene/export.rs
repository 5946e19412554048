//! Writing a [`Model`] out as a scene: a TOML file and, next to it, a directory with the DOF
//! names (`dofs.txt`) and the structural matrices as Matrix Market files (`mass.mtx`,
//! `damping.mtx`, `stiffness.mtx`), the layout an FE export gives. [`Scene::load`] reads it
//! back to the same model: the same names, matrices (symmetric ones to the last bit of their
//! lower triangle), elements (their laws serialised by `typetag`) and loads.
//!
//! ```
//! use hbal::force::CubicSpring;
//! use hbal::scene::{export::{write_scene, SceneSettings}, Scene};
//! use hbal::Model;
//! let model = Model::builder(&["x"])
//!     .mass_diagonal(&[1.0])
//!     .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.02))
//!     .element("spring", &[("x", 1.0)], CubicSpring::new(1.0, 1.0))
//!     .load("x", 1, 0.1, 0.0)
//!     .build()?;
//! let dir = std::env::temp_dir().join(format!("hbal-export-doc-{}", std::process::id()));
//! let file = dir.join("duffing.toml");
//! write_scene(&model, &SceneSettings::new("Duffing", "rad_s", 1.2, 7), &file)?;
//! let scene = Scene::load(&file)?;
//! assert_eq!(scene.model.n_dofs(), 1);
//! assert_eq!(scene.model.elements()[0].name(), "spring");
//! assert_eq!(scene.basis.harmonics(), 7);
//! # std::fs::remove_dir_all(&dir).ok();
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! [`Scene::load`]: super::Scene::load

use super::{matrix_market, SceneError};
use crate::model::SparseMatrix;
use crate::Model;
use serde_json::{json, Map, Value};
use std::path::Path;

/// What a written scene holds besides the model: its description, fundamental, harmonics and
/// solver.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneSettings {
    /// The scene's `description`.
    pub description: String,
    /// Unit of the speed: `rpm`, `hz` or `rad_s`.
    pub speed_unit: String,
    /// The speed in that unit.
    pub speed: f64,
    /// The fundamental's order relative to that speed (e.g. 0.5 for a four-stroke engine's
    /// half orders).
    pub order: f64,
    /// Number of harmonics H.
    pub harmonics: usize,
    /// Samples N per period (`None`: the default for H).
    pub samples: Option<usize>,
    /// Solver method (`newton`, `anderson`, ...).
    pub method: String,
    /// Solver tolerance (`None`: the method's default).
    pub tolerance: Option<f64>,
}

impl SceneSettings {
    /// Order 1, the default samples, Newton with its default tolerance.
    pub fn new(description: &str, speed_unit: &str, speed: f64, harmonics: usize) -> Self {
        Self {
            description: description.into(),
            speed_unit: speed_unit.into(),
            speed,
            order: 1.0,
            harmonics,
            samples: None,
            method: "newton".into(),
            tolerance: None,
        }
    }
}

/// Writes `model` as the scene file `path` (TOML) with its DOF names and matrices in the
/// directory `path` without its extension (`drivetrain.toml` → `drivetrain/`), which is
/// created. Errors name the file that could not be written.
pub fn write_scene(model: &Model, settings: &SceneSettings, path: &Path) -> Result<(), SceneError> {
    let file = path.display().to_string();
    let fail = |what: &Path, e: &dyn std::fmt::Display| SceneError {
        file: what.display().to_string(),
        position: None,
        path: None,
        message: format!("cannot write: {e}"),
    };
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .ok_or_else(|| SceneError {
            file: file.clone(),
            position: None,
            path: None,
            message: "a scene file needs a name (e.g. `drivetrain.toml`)".into(),
        })?;
    let dir = path.with_extension("");
    std::fs::create_dir_all(&dir).map_err(|e| fail(&dir, &e))?;
    let names = model.dof_names();
    let mut listing = String::with_capacity(names.len() * 12);
    for name in names {
        listing.push_str(name);
        listing.push('\n');
    }
    let dofs = dir.join("dofs.txt");
    std::fs::write(&dofs, listing).map_err(|e| fail(&dofs, &e))?;
    let matrices: [(&str, &SparseMatrix); 4] = [
        ("mass", model.mass()),
        ("damping", model.structural_damping()),
        ("stiffness", model.structural_stiffness()),
        ("hysteretic_damping", model.hysteretic()),
    ];
    let mut doc = Map::new();
    doc.insert("description".into(), json!(settings.description));
    doc.insert("dofs".into(), json!({ "file": format!("{stem}/dofs.txt") }));
    for (what, a) in matrices {
        if what != "mass" && a.nnz() == 0 {
            continue;
        }
        let target = dir.join(format!("{what}.mtx"));
        let mut out =
            std::io::BufWriter::new(std::fs::File::create(&target).map_err(|e| fail(&target, &e))?);
        let comment = format!("{what} matrix of {} ({} DOFs, SI units)", stem, a.n());
        matrix_market::write(&mut out, a, &comment).map_err(|e| fail(&target, &e))?;
        std::io::Write::flush(&mut out).map_err(|e| fail(&target, &e))?;
        doc.insert(what.into(), json!({ "file": format!("{stem}/{what}.mtx") }));
    }
    let mut fundamental = Map::new();
    fundamental.insert(settings.speed_unit.clone(), json!(settings.speed));
    if settings.order != 1.0 {
        fundamental.insert("order".into(), json!(settings.order));
    }
    doc.insert("fundamental".into(), Value::Object(fundamental));
    let mut harmonics = Map::new();
    harmonics.insert("count".into(), json!(settings.harmonics));
    if let Some(n) = settings.samples {
        harmonics.insert("samples".into(), json!(n));
    }
    doc.insert("harmonics".into(), Value::Object(harmonics));
    let loads: Vec<Value> = model
        .loads()
        .iter()
        .map(|l| load_value(l, &names[l.dof], settings.order))
        .collect();
    doc.insert("loads".into(), Value::Array(loads));
    let mut solver = Map::new();
    solver.insert("method".into(), json!(settings.method));
    if let Some(t) = settings.tolerance {
        solver.insert("tolerance".into(), json!(t));
    }
    doc.insert("solver".into(), Value::Object(solver));
    let mut elements = Vec::with_capacity(model.elements().len());
    for e in model.elements() {
        if let Some(stage) = e.gear_stage() {
            let mut element = Map::new();
            element.insert("name".into(), json!(e.name()));
            element.insert("type".into(), json!("gear_stage"));
            // The scene re-reads `shaft_order` against its own fundamental order: keep the mesh
            // cycles per period.
            let mut stage = stage.clone();
            stage.shaft_order *= settings.order / stage.fundamental_order;
            let mut fields = serde_json::to_value(&stage).map_err(|x| SceneError {
                file: file.clone(),
                position: None,
                path: Some(format!("element `{}`", e.name())),
                message: format!("its gear stage cannot be written: {x}"),
            })?;
            drop_nulls(&mut fields);
            if let Value::Object(fields) = fields {
                element.extend(fields);
            }
            elements.push(Value::Object(element));
            continue;
        }
        let mut law = serde_json::to_value(e.law()).map_err(|x| SceneError {
            file: file.clone(),
            position: None,
            path: Some(format!("element `{}`", e.name())),
            message: format!("its law cannot be written: {x}"),
        })?;
        drop_nulls(&mut law);
        flatten_offset(&mut law);
        let mut element = Map::new();
        element.insert("name".into(), json!(e.name()));
        let connects: Map<String, Value> = e
            .weights()
            .iter()
            .map(|&(i, w)| (names[i].clone(), json!(w)))
            .collect();
        element.insert("connects".into(), Value::Object(connects));
        if let Value::Object(fields) = law {
            element.extend(fields);
        }
        elements.push(Value::Object(element));
    }
    doc.insert("elements".into(), Value::Array(elements));
    let text = toml::to_string(&Value::Object(doc)).map_err(|e| fail(path, &e))?;
    let header =
        "# Written by hbal (scene::export): the model's matrices and DOF names are in the\n\
                  # directory next to this file.\n";
    std::fs::write(path, format!("{header}{text}")).map_err(|e| fail(path, &e))
}

/// Writes an [`Offset`](crate::force::Offset) law as a scene file has it: the inner law's
/// fields and `offset = u0` (nested offsets summed).
fn flatten_offset(law: &mut Value) {
    let mut u0 = 0.0;
    let mut shifted = false;
    while law.get("type").and_then(Value::as_str) == Some("offset") {
        let Some(inner) = law.get_mut("law").map(Value::take) else {
            return;
        };
        u0 += law.get("offset").and_then(Value::as_f64).unwrap_or(0.0);
        shifted = true;
        *law = inner;
    }
    if let (true, Value::Object(fields)) = (shifted, law) {
        fields.insert("offset".into(), json!(u0));
    }
}

/// Removes `null` fields (unset options), which TOML cannot hold.
fn drop_nulls(v: &mut Value) {
    match v {
        Value::Object(m) => {
            m.retain(|_, x| !x.is_null());
            m.values_mut().for_each(drop_nulls);
        }
        Value::Array(a) => a.iter_mut().for_each(drop_nulls),
        _ => {}
    }
}

/// A load as the scene writes it: `cos`, `sin` and a power law; or a table over speed, its
/// base phasor `b` folded in (`|b| A`, `ψ - arg b`).
fn load_value(l: &crate::model::Load, dof: &str, order: f64) -> Value {
    // The law's rpm are the reference shaft's of its own fundamental order; the scene's
    // reference shaft turns at `Ω / order`.
    let speed = l.speed.as_deref().map(|law| {
        let mut law = law.clone();
        let scale = law.fundamental_order / order;
        match &mut law.rpm {
            crate::model::Speeds::Reference(r) => *r *= scale,
            crate::model::Speeds::Table(t) => t.iter_mut().for_each(|r| *r *= scale),
        }
        law.fundamental_order = order;
        law
    });
    match speed.as_ref() {
        None => json!({ "dof": dof, "order": l.order, "cos": l.cos, "sin": l.sin }),
        Some(law) if !law.is_table() => {
            json!({ "dof": dof, "order": l.order, "cos": l.cos, "sin": l.sin, "speed": law })
        }
        Some(law) => {
            let base = num_complex::Complex64::new(l.cos, l.sin);
            let mut law = law.clone();
            let (size, angle) = (base.norm(), base.arg());
            for a in &mut law.amplitude {
                *a *= size;
            }
            if angle != 0.0 {
                law.phase.resize(law.amplitude.len(), 0.0);
                for p in &mut law.phase {
                    *p -= angle;
                }
            }
            json!({ "dof": dof, "order": l.order, "speed": law })
        }
    }
}
