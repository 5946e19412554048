//! Scene files: a model, its fundamental, harmonics and solver in TOML or JSON (same schema).
//!
//! The schema is documented in `docs/scenes.md`. [`Scene::load`] parses a file, checks every
//! field and builds the [`Model`]; every error names the file and the field path (and, for a
//! syntax error, the line and column). The structural matrices may come from Matrix Market
//! files or inline triplets and the DOF names from a sidecar list (see `matrix.rs`, `dofs.rs`
//! and [`matrix_market`]).
//!
//! ```
//! let text = r#"
//! dofs = ["x"]
//! mass = [[1.0]]
//! damping = [[0.1]]
//! fundamental = { rad_s = 1.2 }
//! harmonics = { count = 7 }
//! loads = [{ dof = "x", order = 1, cos = 0.1 }]
//! [[elements]]
//! name = "spring"
//! type = "cubic_spring"
//! connects = { x = 1.0 }
//! k = 1.0
//! alpha = 1.0
//! "#;
//! let scene = hbal::scene::Scene::from_str(text, "duffing.toml").unwrap();
//! assert_eq!(scene.basis.harmonics(), 7);
//! let err = hbal::scene::Scene::from_str(&text.replace("alpha", "alhpa"), "bad.toml").unwrap_err();
//! assert!(err.to_string().contains("elements[0].alhpa"), "{err}");
//! ```

pub mod bounded_read;
mod dofs;
mod elements;
pub mod export;
mod fundamental;
mod gear_stage;
mod harmonics;
mod line;
mod line_gears;
mod line_modal;
mod loads;
mod matrix;
pub mod matrix_market;
mod overrides;
mod paths;
mod set_parameter;
pub use set_parameter::set_parameter;
mod planetary;
mod solver;
mod torus_choice;
mod torus_plan;

pub use overrides::{HarmonicsOverride, Overrides};
use paths::{field_path, is_json, line_col, non_finite, out_of_range, strip_position};
use solver::SolverSpec;
pub use solver::{check_tolerance, MAX_ITERATIONS, METHODS, MIN_TOLERANCE};
pub use torus_plan::TorusPlan;

use crate::solve::Method;
use crate::{HarmonicBasis, Model};
use serde::Deserialize;
use serde_json::{Map, Value};
use std::path::Path;

/// A scene-file error: file, where, what.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The file.
    pub file: String,
    /// Line and column (1-based) for syntax errors.
    pub position: Option<(usize, usize)>,
    /// The field path, e.g. `elements[1].profile.contact_ratio`.
    pub path: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some((l, c)) = self.position {
            write!(f, ":{l}:{c}")?;
        }
        if let Some(p) = &self.path {
            write!(f, ": {p}")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneError {}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    #[serde(default)]
    description: Option<String>,
    /// Names, `{ file }` or `{ count, prefix }` (see `dofs.rs`).
    dofs: Value,
    /// Dense rows, `{ file }` or `{ triplets, symmetric }` (see `matrix.rs`).
    mass: Value,
    #[serde(default)]
    damping: Option<Value>,
    #[serde(default)]
    stiffness: Option<Value>,
    /// Hysteretic damping H (`+ i H` at every harmonic k >= 1), as `damping`.
    #[serde(default)]
    hysteretic_damping: Option<Value>,
    /// With `harmonics`, the operating point; both may be left out for `modes` and `check`.
    #[serde(default)]
    fundamental: Option<fundamental::Fundamental>,
    #[serde(default)]
    harmonics: Option<harmonics::Harmonics>,
    /// Piston-engine excitation per order and cylinder.
    #[serde(default)]
    engine: Option<crate::model::EngineExcitation>,
    #[serde(default)]
    loads: Vec<loads::LoadSpec>,
    #[serde(default)]
    elements: Vec<Map<String, Value>>,
    #[serde(default)]
    solver: SolverSpec,
}

/// A loaded scene: the model, its discretisation and the chosen solver.
#[derive(Debug)]
pub struct Scene {
    /// The file it came from.
    pub file: String,
    /// Free text from the file.
    pub description: Option<String>,
    /// The model.
    pub model: Model,
    /// Ω, H, N (with automatic harmonics: the first H tried).
    pub basis: HarmonicBasis,
    /// Automatic harmonics (`harmonics = { auto = true, tolerance = 1e-6 }`): H is raised from
    /// `basis` until the estimated error is below the tolerance
    /// ([`solve_auto`](crate::solve::solve_auto)).
    pub auto: Option<crate::solve::AutoHarmonics>,
    /// The solver with its options.
    pub method: Method,
    /// Unit of the scene's speed (`rpm`, `hz` or `rad_s`).
    pub speed_unit: &'static str,
    /// Fundamental Ω (rad/s) per unit of speed (includes `order`).
    pub omega_per_speed: f64,
    /// The fundamental's order relative to the scene's speed (`fundamental.order`, or chosen
    /// from the engine and mesh orders: 0.5 with half orders).
    pub fundamental_order: f64,
    /// `true` if the scene gives `fundamental` and `harmonics`: an operating point that
    /// `solve`, `sweep`, `compare` and `report` need. Without it `basis` is a placeholder
    /// (1000 rpm, H = the highest load or mesh order) and only `modes` of a model linear in
    /// the state and `check` run ([`Scene::require_operating_point`]).
    pub operating_point: bool,
    /// Things the user should know that are not errors (a `loads` order that counts half
    /// orders because the engine table chose the fundamental).
    pub notes: Vec<String>,
    /// The scene on several base frequencies ([`crate::torus`]), where it is solved there:
    /// `harmonics.bases = "torus"`, or `"auto"` (the default) where one fundamental cannot
    /// hold the meshes. `basis` is then the first base's (a placeholder for the one-frequency
    /// analyses, which refuse such a scene).
    pub torus: Option<TorusPlan>,
    solver: SolverSpec,
}

impl Scene {
    /// Reads and builds a scene; `.json` files are JSON, everything else TOML.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = bounded_read::read_text(path).map_err(|e| SceneError {
            file: file.clone(),
            position: None,
            path: None,
            message: format!("cannot read the file: {e}"),
        })?;
        Self::from_str(&text, &file)
    }

    /// Parses scene text; the format follows the name's extension (`.json` or TOML). Files the
    /// scene names (`mass = { file = "m.mtx" }`, `dofs = { file = "dofs.txt" }`) are relative
    /// to the directory of `file` if it exists, else to the current directory.
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str, file: &str) -> Result<Scene, SceneError> {
        Self::from_value(Self::parse_value(text, file)?, file)
    }

    /// Builds a scene from an already parsed document (see [`Scene::parse_value`],
    /// [`set_parameter`]).
    pub fn from_value(mut value: Value, file: &str) -> Result<Scene, SceneError> {
        let err = |position, path: Option<String>, message: String| SceneError {
            file: file.to_string(),
            position,
            path,
            message,
        };
        // Types and field names first (an unknown field, a whole number given as 1e300, are
        // named as such), then the magnitude of every number before anything is built.
        let range = out_of_range(&value, String::new());
        // The shaft-line vocabulary becomes the matrices it stands for.
        let removed =
            line::expand(&mut value).map_err(|(path, message)| err(None, Some(path), message))?;
        let parsed: SceneFile = serde_path_to_error::deserialize(value).map_err(|e| {
            let path = e.path().to_string();
            let message = whole_numbers_named(&e.into_inner().to_string());
            let path = field_path(path, &message);
            err(None, (path != ".").then_some(path), message)
        })?;
        if let Some((path, x)) = range {
            return Err(err(
                None,
                Some(path),
                format!(
                    "must be 0 or between {:e} and {:e} in magnitude, got {x:e}",
                    crate::error::MIN_MAGNITUDE,
                    crate::error::MAX_MAGNITUDE
                ),
            ));
        }
        parsed.build(file).map_err(|mut e| {
            // A disk a rigid gear removed, named where only loads may name it.
            if let Some((gone, kept, f)) = removed
                .iter()
                .find(|r| e.message.contains(&format!("unknown DOF `{}`", r.0)))
            {
                e.message.push_str(&format!(
                    " (a rigid gear removed `{gone}`: its angle is {f} × `{kept}`'s; loads on it move there, other tables name `{kept}`)"
                ));
            }
            e
        })
    }

    /// Parses scene text into a document tree (JSON values) with the file's syntax checks.
    pub fn parse_value(text: &str, file: &str) -> Result<Value, SceneError> {
        let err = |position, path: Option<String>, message: String| SceneError {
            file: file.to_string(),
            position,
            path,
            message,
        };
        let value: Value = if is_json(file) {
            serde_json::from_str(text).map_err(|e| {
                err(
                    Some((e.line(), e.column())),
                    None,
                    strip_position(&e.to_string()),
                )
            })?
        } else {
            let v: toml::Value = toml::from_str(text).map_err(|e| {
                let pos = e.span().map(|s| line_col(text, s.start));
                err(pos, None, e.message().trim().replace('\n', "; "))
            })?;
            if let Some((path, x)) = non_finite(&v, String::new()) {
                return Err(err(
                    None,
                    Some(path),
                    format!("must be a finite number, got {x}"),
                ));
            }
            serde_json::to_value(v).map_err(|e| err(None, None, e.to_string()))?
        };
        Ok(value)
    }
}

impl SceneFile {
    fn build(self, file: &str) -> Result<Scene, SceneError> {
        let err = |path: &str, message: String| SceneError {
            file: file.to_string(),
            position: None,
            path: Some(path.to_string()),
            message,
        };
        let structure = matrix::Structure::read(
            &self.dofs,
            &self.mass,
            [
                self.damping.as_ref(),
                self.stiffness.as_ref(),
                self.hysteretic_damping.as_ref(),
            ],
            &matrix::base_dir(file),
        )
        .map_err(|(path, message)| err(&path, message))?;
        let dofs = &structure.dofs;
        let known: std::collections::HashSet<&str> =
            dofs.names.iter().map(String::as_str).collect();
        let builder = structure.builder();
        let operating_point = match (&self.fundamental, &self.harmonics) {
            (Some(_), Some(_)) => true,
            (None, None) => false,
            (Some(_), None) => return Err(err("harmonics", "is missing: an operating point needs `fundamental` and `harmonics` (leave both out for `hbal modes` and `hbal check` of a linear model)".into())),
            (None, Some(_)) => return Err(err("fundamental", "is missing: an operating point needs `fundamental` and `harmonics` (leave both out for `hbal modes` and `hbal check` of a linear model)".into())),
        };
        let fundamental = self
            .fundamental
            .unwrap_or_else(fundamental::Fundamental::placeholder);
        let mut elements = self.elements;
        let one = fundamental.speed(self.engine.as_ref(), &elements);
        let meshes = torus_plan::meshes(&elements);
        let torus_why = self.harmonics.as_ref().and_then(|h| {
            let kept = if h.auto {
                h.max
                    .or(Some(crate::solve::AutoHarmonics::default().max_harmonics))
            } else {
                h.count
            };
            torus_plan::choose(h.bases, &meshes, &one, kept)
        });
        let (speed, layout) = match torus_why {
            None => (one.map_err(|(path, message)| err(&path, message))?, None),
            Some(why) => {
                let f0 = fundamental
                    .speed(self.engine.as_ref(), &[])
                    .map_err(|(path, message)| err(&path, message))?;
                // `harmonics.count` covers `count × f / f0` harmonics of the first base.
                let count_cap = self.harmonics.as_ref().and_then(|h| h.count).map(|h| {
                    let f = one.as_ref().map_or(f0.order, |s| s.order);
                    (h as f64 * f / f0.order).floor() as usize
                });
                let layout = torus_plan::Layout::new(
                    &mut elements,
                    &meshes,
                    f0.order,
                    self.engine.is_some(),
                    count_cap,
                    why,
                )
                .map_err(|(path, message)| err(&path, message))?;
                (f0, Some(layout))
            }
        };
        if layout.is_none() {
            if let Some(i) = elements.iter().position(|e| e.contains_key("base")) {
                return Err(err(&format!("elements[{i}].base"), "binds the element to a base of the torus, but this scene is solved on one fundamental (`harmonics.bases = \"torus\"` puts it on the torus)".into()));
            }
        }
        let builder = loads::add(
            builder,
            &self.loads,
            self.engine.as_ref(),
            dofs,
            &known,
            speed.order,
        )
        .map_err(|(path, message)| err(&path, message))?;
        let stage_order = |name: &str| layout.as_ref().and_then(|l| l.stage_order(name));
        let builder = elements::add(builder, elements, dofs, &known, speed.order, &stage_order)
            .map_err(|(path, message)| err(&path, message))?;
        let model = builder.build().map_err(|e| {
            let (path, message) = structure.model_error(&e);
            err(&path, message)
        })?;

        let mut notes = Vec::new();
        if speed.chosen && speed.order != 1.0 && self.loads.iter().any(|l| l.order > 0) {
            notes.push(format!(
                "the engine's orders make the fundamental {} of the {} speed: `loads` orders \
                 count harmonics of it (order 2 there is shaft order {})",
                speed.order,
                speed.unit,
                2.0 * speed.order
            ));
        }
        let harmonics = self
            .harmonics
            .unwrap_or_else(|| harmonics::Harmonics::placeholder(model.max_order().max(1)));
        let torus = layout
            .map(|l| l.finish(&harmonics, &model, &speed))
            .transpose()
            .map_err(|(path, message)| err(&path, message))?;
        let (basis, auto) = match &torus {
            None => harmonics.basis(speed.omega),
            Some(plan) => harmonics.torus_basis(speed.omega, plan.caps[0]),
        }
        .map_err(|(path, message)| err(&path, message))?;
        let method = self
            .solver
            .method(None)
            .map_err(|(path, message)| err(&path, message))?;
        Ok(Scene {
            file: file.to_string(),
            description: self.description,
            model,
            basis,
            auto,
            method,
            speed_unit: speed.unit,
            omega_per_speed: speed.per_unit * speed.order,
            fundamental_order: speed.order,
            operating_point,
            notes,
            torus,
            solver: self.solver,
        })
    }
}

impl Scene {
    /// An error for `analysis` (`solve`, `sweep`, ...) where the scene gives no operating
    /// point (`fundamental` and `harmonics`).
    pub fn require_operating_point(&self, analysis: &str) -> crate::Result<()> {
        if let Some(plan) = &self.torus {
            return Err(crate::Error::InvalidElement {
                context: format!("`{analysis}`"),
                reason: format!("runs on one fundamental, and this scene is solved on several base frequencies ({}): `hbal solve` and `hbal sweep` solve it there (in the library: analysis::torus_solve, torus_sweep); `harmonics.bases = \"one\"` puts it on one fundamental", plan.why),
            });
        }
        if self.operating_point {
            return Ok(());
        }
        Err(crate::Error::InvalidElement {
            context: format!("`{analysis}`"),
            reason: "needs the scene's operating point: give `fundamental` and `harmonics` (hbal modes of a linear model and hbal check need none)".into(),
        })
    }
}

/// The built-in element types (users' laws compiled in are accepted too).
pub fn known_types() -> String {
    "linear_spring, mesh_stiffness, backlash, cubic_spring, gap_contact, stop_spring, friction, jenkins, \
     quadratic_damper, polynomial_spring, gear_stage, planetary"
        .to_string()
}

/// serde's names of whole-number types in a message, as a user reads them ("expected usize"
/// says nothing to an engineer).
fn whole_numbers_named(message: &str) -> String {
    ["usize", "u64", "u32", "u16", "u8"]
        .iter()
        .fold(message.to_string(), |m, t| {
            m.replace(&format!("expected {t}"), "expected a whole number >= 0")
        })
}
