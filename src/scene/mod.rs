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

mod dofs;
pub mod export;
mod fundamental;
mod gear_stage;
mod matrix;
pub mod matrix_market;

use crate::force::ForceLaw;
use crate::solve::{Anderson, Broyden, FixedPoint, Method, Newton};
use crate::{HarmonicBasis, Model};
use serde::Deserialize;
use serde_json::{Map, Value};
use std::collections::BTreeMap;
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
struct Harmonics {
    count: Option<usize>,
    samples: Option<usize>,
    #[serde(default)]
    auto: bool,
    tolerance: Option<f64>,
    max: Option<usize>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadSpec {
    dof: String,
    order: usize,
    #[serde(default)]
    cos: f64,
    #[serde(default)]
    sin: f64,
}

/// Solver settings; unset fields take the method's defaults.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct SolverSpec {
    method: Option<String>,
    gamma: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<usize>,
    depth: Option<usize>,
}

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
    fundamental: fundamental::Fundamental,
    harmonics: Harmonics,
    /// Piston-engine excitation per order and cylinder.
    #[serde(default)]
    engine: Option<crate::model::EngineExcitation>,
    #[serde(default)]
    loads: Vec<LoadSpec>,
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
    solver: SolverSpec,
}

/// Names of the solver methods.
pub const METHODS: [&str; 4] = ["fixed_point", "newton", "broyden", "anderson"];

impl Scene {
    /// Reads and builds a scene; `.json` files are JSON, everything else TOML.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
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
    pub fn from_value(value: Value, file: &str) -> Result<Scene, SceneError> {
        let err = |position, path: Option<String>, message: String| SceneError {
            file: file.to_string(),
            position,
            path,
            message,
        };
        let parsed: SceneFile = serde_path_to_error::deserialize(value).map_err(|e| {
            let path = e.path().to_string();
            let message = e.into_inner().to_string();
            let path = field_path(path, &message);
            err(None, (path != ".").then_some(path), message)
        })?;
        parsed.build(file)
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

/// The path of the first NaN or infinite float in a TOML value (JSON has none).
fn non_finite(v: &toml::Value, path: String) -> Option<(String, f64)> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Some((path, *x)),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| non_finite(x, format!("{path}[{i}]"))),
        toml::Value::Table(t) => t.iter().find_map(|(k, x)| {
            let p = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            non_finite(x, p)
        }),
        _ => None,
    }
}

/// Where in `v` a key named `key` (or, with `as_value`, a string equal to it) sits, as a path.
fn locate(v: &Value, needle: &str, as_value: bool, path: String) -> Option<String> {
    match v {
        Value::Object(map) => map.iter().find_map(|(k, x)| {
            let p = if path.is_empty() {
                k.clone()
            } else {
                format!("{path}.{k}")
            };
            if (!as_value && k == needle) || (as_value && x.as_str() == Some(needle)) {
                Some(p)
            } else {
                locate(x, needle, as_value, p)
            }
        }),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| locate(x, needle, as_value, format!("{path}[{i}]"))),
        _ => None,
    }
}

/// The first back-quoted word of a serde message.
fn quoted(message: &str) -> Option<&str> {
    message.split('`').nth(1)
}

/// For "unknown field `x`" errors, the path of the offending field itself.
fn field_path(path: String, message: &str) -> String {
    let Some(rest) = message.strip_prefix("unknown field `") else {
        return path;
    };
    let Some(name) = rest.split('`').next() else {
        return path;
    };
    if path == "." || path.is_empty() {
        name.to_string()
    } else if path == name || path.ends_with(&format!(".{name}")) {
        path
    } else {
        format!("{path}.{name}")
    }
}

/// `.json` (any case) is JSON; everything else TOML.
fn is_json(file: &str) -> bool {
    file.to_ascii_lowercase().ends_with(".json")
}

fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
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
            self.damping.as_ref(),
            self.stiffness.as_ref(),
            &matrix::base_dir(file),
        )
        .map_err(|(path, message)| err(&path, message))?;
        let dofs = &structure.dofs;
        let known: std::collections::HashSet<&str> =
            dofs.names.iter().map(String::as_str).collect();
        let mut builder = structure.builder();
        let speed = self
            .fundamental
            .speed(self.engine.as_ref(), &self.elements)
            .map_err(|(path, message)| err(&path, message))?;
        if let Some(engine) = &self.engine {
            for (i, dof) in engine.cylinder_dofs().iter().enumerate() {
                if !known.contains(dof.as_str()) {
                    let path = match engine.cylinders {
                        crate::model::Cylinders::Count(_) => "engine.dof".to_string(),
                        crate::model::Cylinders::Dofs(_) => format!("engine.cylinders[{i}]"),
                    };
                    let message =
                        format!("unknown DOF `{dof}` (the scene has: {})", dofs.listing());
                    return Err(err(&path, message));
                }
            }
            let loads = engine
                .validate("engine")
                .and_then(|()| engine.loads(speed.order))
                .map_err(|e| match &e {
                    crate::Error::InvalidParameter { name, .. } => {
                        err(&format!("engine.{name}"), e.to_string())
                    }
                    _ => err("engine", e.to_string()),
                })?;
            for (dof, k, c, s) in loads {
                builder = builder.load(&dof, k, c, s);
            }
        }
        for (i, l) in self.loads.iter().enumerate() {
            if !known.contains(l.dof.as_str()) {
                return Err(err(
                    &format!("loads[{i}].dof"),
                    format!(
                        "unknown DOF `{}` (the scene has: {})",
                        l.dof,
                        dofs.listing()
                    ),
                ));
            }
            builder = builder.load(&l.dof, l.order, l.cos, l.sin);
        }
        for (i, e) in self.elements.into_iter().enumerate() {
            let at = |field: &str| format!("elements[{i}].{field}");
            let mut e = e;
            let name = match e.remove("name") {
                Some(Value::String(s)) => s,
                Some(_) => return Err(err(&at("name"), "must be a string".into())),
                None => format!("element {i}"),
            };
            if e.get("type").and_then(Value::as_str) == Some("gear_stage") {
                e.remove("type");
                let stage = gear_stage::read(e, &name, dofs, |f| {
                    if f.is_empty() {
                        format!("elements[{i}]")
                    } else {
                        at(f)
                    }
                })
                .map_err(|(path, message)| err(&path, message))?;
                builder = builder.gear_stage(&name, stage.with_fundamental_order(speed.order));
                continue;
            }
            let connects: BTreeMap<String, f64> = match e.remove("connects") {
                Some(v) => serde_path_to_error::deserialize(v).map_err(|x| {
                    err(
                        &at("connects"),
                        format!("{} (a table DOF = weight)", x.into_inner()),
                    )
                })?,
                None => {
                    return Err(err(
                        &format!("elements[{i}]"),
                        "missing field `connects` (a table DOF = weight)".into(),
                    ))
                }
            };
            for dof in connects.keys() {
                if !known.contains(dof.as_str()) {
                    return Err(err(
                        &at("connects"),
                        format!("unknown DOF `{dof}` (the scene has: {})", dofs.listing()),
                    ));
                }
            }
            // `offset = u0` on any element: the law on `u - u0` (removed before the law's own
            // fields are read; a law's own field may not be called `offset`).
            let offset = match e.remove("offset") {
                Some(v) => match v.as_f64() {
                    Some(x) => Some(x),
                    None => {
                        return Err(err(
                            &at("offset"),
                            format!("must be a number (m or rad), got {v}"),
                        ))
                    }
                },
                None => None,
            };
            if e.get("type").and_then(|t| t.as_str()) == Some("offset") {
                return Err(err(
                    &at("type"),
                    "`offset` is not an element type: give the law's own `type` and the \
                     field `offset = u0` next to it"
                        .into(),
                ));
            }
            if !e.contains_key("type") {
                return Err(err(
                    &format!("elements[{i}]"),
                    format!("missing field `type` (one of: {})", known_types()),
                ));
            }
            let type_name = e
                .get("type")
                .and_then(|t| t.as_str())
                .unwrap_or("")
                .to_string();
            let element = Value::Object(e);
            let law: Box<dyn ForceLaw> = serde_path_to_error::deserialize(element.clone())
                .map_err(|x| {
                    let p = x.path().to_string();
                    let mut message = x.into_inner().to_string();
                    // typetag buffers the element, so serde's path stops at it: find the
                    // offending key or value inside the element ourselves.
                    let inner = if message.starts_with("unknown field") {
                        quoted(&message).and_then(|k| locate(&element, k, false, String::new()))
                    } else if message.starts_with("unknown variant") {
                        quoted(&message).and_then(|v| {
                            locate(&element, v, true, String::new())
                                .or_else(|| locate(&element, v, false, String::new()))
                        })
                    } else {
                        None
                    };
                    let path = match inner {
                        Some(p) => at(&p),
                        None => {
                            let p = field_path(p, &message);
                            if p == "." {
                                format!("elements[{i}]")
                            } else {
                                at(&p)
                            }
                        }
                    };
                    if quoted(&message) == Some(type_name.as_str()) {
                        message = format!("{message}; known element types: {}", known_types());
                    }
                    err(&path, message)
                })?;
            let law = match offset {
                Some(u0) => Box::new(crate::force::Offset::boxed(u0, law)),
                None => law,
            };
            let weights: Vec<(&str, f64)> =
                connects.iter().map(|(d, w)| (d.as_str(), *w)).collect();
            builder = builder.element_boxed(&name, &weights, law);
        }
        let model = builder.build().map_err(|e| {
            let (path, message) = structure.model_error(&e);
            err(&path, message)
        })?;

        let omega = speed.omega;
        let hs = &self.harmonics;
        let auto = if hs.auto {
            let defaults = crate::solve::AutoHarmonics::default();
            let tolerance = hs.tolerance.unwrap_or(defaults.tolerance);
            if !(tolerance.is_finite() && (1e-14..1.0).contains(&tolerance)) {
                return Err(err(
                    "harmonics.tolerance",
                    format!(
                        "must be in [1e-14, 1) (the estimate stops at rounding), got {tolerance}"
                    ),
                ));
            }
            let max_harmonics = hs.max.unwrap_or(defaults.max_harmonics);
            let limit = HarmonicBasis::MAX_HARMONICS / 2;
            if max_harmonics > limit {
                return Err(err(
                    "harmonics.max",
                    format!(
                        "must be at most {limit} (its refinement doubles it), got {max_harmonics}"
                    ),
                ));
            }
            let first = hs.count.unwrap_or(8);
            if first == 0 {
                return Err(err(
                    "harmonics.count",
                    "must be at least 1 with `auto = true` (H = 0 is a static analysis)"
                        .to_string(),
                ));
            }
            if max_harmonics < first.max(1) {
                return Err(err(
                    "harmonics.max",
                    format!("must be at least the first H ({first}), got {max_harmonics}"),
                ));
            }
            Some(crate::solve::AutoHarmonics {
                tolerance,
                max_harmonics,
                ..Default::default()
            })
        } else {
            for (field, given) in [
                ("tolerance", hs.tolerance.is_some()),
                ("max", hs.max.is_some()),
            ] {
                if given {
                    return Err(err(
                        &format!("harmonics.{field}"),
                        "only applies with `auto = true`".to_string(),
                    ));
                }
            }
            None
        };
        let count = match (hs.count, hs.auto) {
            (Some(c), _) => c,
            (None, true) => 8,
            (None, false) => {
                return Err(err(
                    "harmonics.count",
                    "is required (or `auto = true`)".to_string(),
                ))
            }
        };
        let mut basis =
            HarmonicBasis::new(omega, count).map_err(|e| err("harmonics.count", e.to_string()))?;
        if let Some(s) = self.harmonics.samples {
            basis = basis
                .with_samples(s)
                .map_err(|e| err("harmonics.samples", e.to_string()))?;
        }
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
            solver: self.solver,
        })
    }
}

impl SolverSpec {
    /// The method, optionally overriding the name.
    fn method(&self, name: Option<&str>) -> Result<Method, (String, String)> {
        let name = name.or(self.method.as_deref()).unwrap_or("newton");
        let e = |field: &str, x: crate::Error| (format!("solver.{field}"), x.to_string());
        let method = match name {
            "fixed_point" => {
                let mut o = FixedPoint::new();
                if let Some(g) = self.gamma {
                    o = o.with_gamma(g).map_err(|x| e("gamma", x))?;
                }
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::FixedPoint(o)
            }
            "newton" => {
                let mut o = Newton::new();
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::Newton(o)
            }
            "broyden" => {
                let mut o = Broyden::new();
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::Broyden(o)
            }
            "anderson" => {
                let mut o = Anderson::new();
                if let Some(g) = self.gamma {
                    o = o.with_gamma(g).map_err(|x| e("gamma", x))?;
                }
                if let Some(d) = self.depth {
                    o = o.with_depth(d).map_err(|x| e("depth", x))?;
                }
                if let Some(t) = self.tolerance {
                    o = o.with_tolerance(t).map_err(|x| e("tolerance", x))?;
                }
                if let Some(m) = self.max_iterations {
                    o = o.with_max_iterations(m);
                }
                Method::Anderson(o)
            }
            other => {
                return Err((
                    "solver.method".into(),
                    format!("unknown method `{other}` (one of: {})", METHODS.join(", ")),
                ))
            }
        };
        Ok(method)
    }
}

/// Sets the number at `path` (e.g. `elements[0].alpha`, `loads[1].cos`, `damping[0][0]`,
/// `fundamental.rpm`) in a parsed scene document; errors name what is missing.
pub fn set_parameter(doc: &mut Value, path: &str, x: f64) -> Result<(), String> {
    let mut cur = doc;
    let mut tokens = Vec::new();
    for part in path.split('.') {
        let (key, rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if !key.is_empty() {
            tokens.push(Err(key.to_string()));
        }
        for idx in rest.split('[').skip(1) {
            let i: usize = idx
                .trim_end_matches(']')
                .parse()
                .map_err(|_| format!("`{path}`: `[{idx}` is not an index"))?;
            tokens.push(Ok(i));
        }
    }
    for t in &tokens {
        cur = match t {
            Err(k) => cur
                .get_mut(k.as_str())
                .ok_or_else(|| format!("`{path}`: no field `{k}`"))?,
            Ok(i) => cur
                .get_mut(*i)
                .ok_or_else(|| format!("`{path}`: no entry [{i}]"))?,
        };
    }
    if !cur.is_number() {
        return Err(format!("`{path}` is not a number in the scene"));
    }
    *cur = serde_json::json!(x);
    Ok(())
}

/// The built-in element types (users' laws compiled in are accepted too).
pub fn known_types() -> String {
    "linear_spring, mesh_stiffness, backlash, cubic_spring, gap_contact, stop_spring, friction, jenkins, \
     quadratic_damper, polynomial_spring, gear_stage"
        .to_string()
}

impl Scene {
    /// The scene's solver settings applied to another method (for `--method` and `compare`);
    /// options meaningless for that method (γ for Newton) are ignored.
    pub fn method_named(&self, name: &str) -> Result<Method, SceneError> {
        let spec = SolverSpec {
            method: None,
            ..self.solver.clone()
        };
        let spec = match name {
            "newton" | "broyden" => SolverSpec {
                gamma: None,
                depth: None,
                ..spec
            },
            "fixed_point" => SolverSpec {
                depth: None,
                ..spec
            },
            _ => spec,
        };
        spec.method(Some(name))
            .map_err(|(path, message)| SceneError {
                file: self.file.clone(),
                position: None,
                path: Some(if name_is_known(name) {
                    path
                } else {
                    "--method".into()
                }),
                message,
            })
    }
}

fn name_is_known(name: &str) -> bool {
    METHODS.contains(&name)
}
