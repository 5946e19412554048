//! The scene's structural matrices (`mass`, `damping`, `stiffness`) and DOFs: dense rows, a
//! Matrix Market file from an FE program, or inline triplets.
//!
//! ```toml
//! dofs = { file = "dofs.txt" }                   # or a list, or { count = 3, prefix = "x" }
//! mass = { file = "chain/mass.mtx" }             # relative to the scene file's directory
//! damping = [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]
//! stiffness = { triplets = [[1, 1, 2.0], [2, 1, -1.0], [2, 2, 1.0]], symmetric = true }
//! ```
//!
//! Triplets are `[row, column, value]` with 1-based indices, as in Matrix Market; repeated
//! positions add up; `symmetric = true` means one triangle is given and mirrored. Files and
//! triplets reach the model through [`ModelBuilder::mass_triplets`] and its siblings; dense rows
//! through [`ModelBuilder::mass`]. Every error names the field and, for a file, the file and
//! line.
//!
//! ```
//! let text = r#"
//! dofs = { count = 2, prefix = "x" }
//! mass = { triplets = [[1, 1, 1.0], [2, 2, 1.0]] }
//! stiffness = { triplets = [[1, 1, 2.0], [2, 1, -1.0], [2, 2, 1.0]], symmetric = true }
//! fundamental = { rad_s = 0.5 }
//! harmonics = { count = 1 }
//! "#;
//! let scene = hbal::scene::Scene::from_str(text, "chain.toml").unwrap();
//! assert_eq!(scene.model.dof_names(), ["x.1", "x.2"]);
//! assert_eq!(scene.model.k0().get(0, 1), -1.0);
//! let bad = text.replace("[2, 2, 1.0]]", "[3, 3, 1.0]]");
//! let err = hbal::scene::Scene::from_str(&bad, "chain.toml").unwrap_err().to_string();
//! assert!(err.contains("mass.triplets[1]: row 3 is outside the 2 DOFs"), "{err}");
//! ```
//!
//! [`ModelBuilder::mass_triplets`]: crate::model::ModelBuilder::mass_triplets
//! [`ModelBuilder::mass`]: crate::model::ModelBuilder::mass

use super::dofs::{self, Dofs};
use super::matrix_market;
use crate::model::ModelBuilder;
use crate::Model;
use nalgebra::DMatrix;
use serde::Deserialize;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A `(field path, message)` error, turned into a `SceneError` by the caller.
type FieldError = (String, String);

/// One matrix as given.
#[derive(Debug)]
enum Source {
    /// Dense rows.
    Dense(DMatrix<f64>),
    /// A file or inline triplets, 0-based and mirrored where symmetric.
    Triplets {
        entries: Vec<(usize, usize, f64)>,
        /// `mass.file` or `mass.triplets`.
        field: String,
        /// The file's path, or `mass.triplets`.
        origin: String,
    },
}

/// `{ file = ... }` or `{ triplets = ..., symmetric = ... }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MatrixSpec {
    file: Option<String>,
    triplets: Option<Vec<Value>>,
    symmetric: Option<bool>,
}

/// The DOFs and the structural matrices of a scene, read and checked against each other.
#[derive(Debug)]
pub(super) struct Structure {
    /// The DOFs.
    pub(super) dofs: Dofs,
    mass: Source,
    damping: Option<Source>,
    stiffness: Option<Source>,
    hysteretic: Option<Source>,
}

/// The directory that paths in the scene are relative to: the scene file's, if it exists, else
/// the current directory.
pub(super) fn base_dir(scene_file: &str) -> PathBuf {
    match Path::new(scene_file).parent() {
        Some(p) if !p.as_os_str().is_empty() && p.is_dir() => p.to_path_buf(),
        _ => PathBuf::new(),
    }
}

impl Structure {
    /// Reads `dofs`, `mass`, `damping`, `stiffness` and `hysteretic_damping`; files are
    /// relative to `base`.
    pub(super) fn read(
        dofs: &Value,
        mass: &Value,
        [damping, stiffness, hysteretic]: [Option<&Value>; 3],
        base: &Path,
    ) -> Result<Structure, FieldError> {
        let dofs = dofs::read(dofs, base)?;
        let matrix = |name, v| read_matrix(name, v, &dofs, base);
        Ok(Structure {
            mass: matrix("mass", mass)?,
            damping: damping.map(|v| matrix("damping", v)).transpose()?,
            stiffness: stiffness.map(|v| matrix("stiffness", v)).transpose()?,
            hysteretic: hysteretic
                .map(|v| matrix("hysteretic_damping", v))
                .transpose()?,
            dofs,
        })
    }

    /// A model builder with the DOFs and matrices.
    pub(super) fn builder(&self) -> ModelBuilder {
        let names: Vec<&str> = self.dofs.names.iter().map(String::as_str).collect();
        let mut b = Model::builder(&names);
        b = match &self.mass {
            Source::Dense(m) => b.mass(m.clone()),
            Source::Triplets { entries, .. } => b.mass_triplets(entries),
        };
        b = match &self.damping {
            None => b,
            Some(Source::Dense(m)) => b.damping(m.clone()),
            Some(Source::Triplets { entries, .. }) => b.damping_triplets(entries),
        };
        b = match &self.stiffness {
            None => b,
            Some(Source::Dense(m)) => b.stiffness(m.clone()),
            Some(Source::Triplets { entries, .. }) => b.stiffness_triplets(entries),
        };
        match &self.hysteretic {
            None => b,
            Some(Source::Dense(m)) => b.hysteretic(m.clone()),
            Some(Source::Triplets { entries, .. }) => b.hysteretic_triplets(entries),
        }
    }

    /// Where a model-building error belongs: a mass matrix from a file or triplets is named,
    /// with the largest asymmetry if that is the problem; everything else is `model`.
    pub(super) fn model_error(&self, e: &crate::Error) -> FieldError {
        let (
            crate::Error::MassNotPositiveDefinite { reason },
            Source::Triplets {
                entries,
                field,
                origin,
            },
        ) = (e, &self.mass)
        else {
            return ("model".into(), e.to_string());
        };
        let mut message = format!("{e} (the mass matrix from {origin})");
        if reason.starts_with("not symmetric") {
            if let Some((i, j, a, b)) = largest_asymmetry(entries) {
                message += &format!(
                    "; row {i}, column {j} is {a:e} but row {j}, column {i} is {b:e} (1-based)"
                );
            }
        }
        (field.clone(), message)
    }
}

/// Reads one matrix field.
fn read_matrix(name: &str, value: &Value, dofs: &Dofs, base: &Path) -> Result<Source, FieldError> {
    let n = dofs.names.len();
    match value {
        Value::Array(_) => dense(name, value, n).map(Source::Dense),
        Value::Object(_) => {
            let spec: MatrixSpec = serde_path_to_error::deserialize(value).map_err(|x| {
                let path = x.path().to_string();
                let message = x.into_inner().to_string();
                let path = super::field_path(path, &message);
                let path = if path == "." {
                    name.to_string()
                } else {
                    format!("{name}.{path}")
                };
                (path, message)
            })?;
            match spec {
                MatrixSpec {
                    file: Some(file),
                    triplets: None,
                    symmetric: None,
                } => from_file(name, &base.join(file), dofs),
                MatrixSpec {
                    file: None,
                    triplets: Some(t),
                    symmetric,
                } => from_triplets(name, &t, symmetric.unwrap_or(false), dofs),
                MatrixSpec {
                    file: Some(_),
                    symmetric: Some(_),
                    ..
                } => Err((
                    format!("{name}.symmetric"),
                    "applies to `triplets` only: a Matrix Market file states its symmetry in its \
                     header"
                        .into(),
                )),
                _ => Err((
                    name.to_string(),
                    "give exactly one of `file` (a Matrix Market file) and `triplets`".into(),
                )),
            }
        }
        other => Err((
            name.to_string(),
            format!(
                "invalid type: {}, expected a list of rows, `{{ file = \"{name}.mtx\" }}` or \
                 `{{ triplets = [[row, column, value], ...] }}`",
                describe(other)
            ),
        )),
    }
}

/// Dense rows, n × n.
fn dense(name: &str, value: &Value, n: usize) -> Result<DMatrix<f64>, FieldError> {
    let rows: Vec<Vec<f64>> = serde_path_to_error::deserialize(value)
        .map_err(|x| (format!("{name}{}", x.path()), x.into_inner().to_string()))?;
    if rows.len() != n {
        return Err((
            name.to_string(),
            format!("expected {n} rows (one per DOF), got {}", rows.len()),
        ));
    }
    for (i, r) in rows.iter().enumerate() {
        if r.len() != n {
            return Err((
                format!("{name}[{i}]"),
                format!("expected {n} columns (one per DOF), got {}", r.len()),
            ));
        }
    }
    Ok(DMatrix::from_fn(n, n, |i, j| rows[i][j]))
}

/// A Matrix Market file, n × n.
fn from_file(name: &str, path: &Path, dofs: &Dofs) -> Result<Source, FieldError> {
    let field = format!("{name}.file");
    let m = matrix_market::read(path).map_err(|e| (field.clone(), e.to_string()))?;
    let n = dofs.names.len();
    if m.rows != n || m.cols != n {
        return Err((
            field,
            format!(
                "{}:{}: the matrix is {} x {}, but the scene has {n} DOFs{}",
                path.display(),
                m.size_line,
                m.rows,
                m.cols,
                dofs.origin_note()
            ),
        ));
    }
    Ok(Source::Triplets {
        entries: m.entries,
        field,
        origin: path.display().to_string(),
    })
}

/// Inline `[row, column, value]` triplets, 1-based.
fn from_triplets(
    name: &str,
    triplets: &[Value],
    symmetric: bool,
    dofs: &Dofs,
) -> Result<Source, FieldError> {
    let n = dofs.names.len();
    let mut entries = Vec::with_capacity(triplets.len() * if symmetric { 2 } else { 1 });
    // The first entry above and below the diagonal, for `symmetric = true`.
    let (mut above, mut below) = (None, None);
    for (k, t) in triplets.iter().enumerate() {
        let at = || format!("{name}.triplets[{k}]");
        let Some([i, j, v]) = t.as_array().map(Vec::as_slice) else {
            return Err((at(), format!("expected [row, column, value], got {t}")));
        };
        let index = |what: &str, x: &Value| -> Result<usize, FieldError> {
            let Some(i) = x.as_u64().filter(|&i| i >= 1) else {
                return Err((
                    at(),
                    format!("{what} must be a whole number ≥ 1 (indices are 1-based), got {x}"),
                ));
            };
            if i > n as u64 {
                return Err((
                    at(),
                    format!(
                        "{what} {i} is outside the {n} DOFs (indices 1 to {n}){}",
                        dofs.origin_note()
                    ),
                ));
            }
            Ok(i as usize - 1)
        };
        let (i, j) = (index("row", i)?, index("column", j)?);
        let Some(v) = v.as_f64().filter(|v| v.is_finite()) else {
            return Err((at(), format!("value must be a finite number, got {v}")));
        };
        if symmetric {
            let side = if i < j { &mut above } else { &mut below };
            if i != j {
                side.get_or_insert(k);
            }
            if let (Some(a), Some(b)) = (above, below) {
                return Err((
                    at(),
                    format!(
                        "with `symmetric = true` give one triangle only, but triplets[{}] lies \
                         above the diagonal and triplets[{}] below it",
                        a, b
                    ),
                ));
            }
        }
        entries.push((i, j, v));
        if symmetric && i != j {
            entries.push((j, i, v));
        }
    }
    Ok(Source::Triplets {
        entries,
        field: format!("{name}.triplets"),
        origin: format!("{name}.triplets"),
    })
}

/// The largest `|a_ij - a_ji|` of assembled triplets: (row, column) 1-based and both values.
fn largest_asymmetry(entries: &[(usize, usize, f64)]) -> Option<(usize, usize, f64, f64)> {
    let mut sum: BTreeMap<(usize, usize), f64> = BTreeMap::new();
    for &(i, j, v) in entries {
        *sum.entry((i, j)).or_insert(0.0) += v;
    }
    let get = |i, j| sum.get(&(i, j)).copied().unwrap_or(0.0);
    sum.keys()
        .filter(|(i, j)| i != j)
        .map(|&(i, j)| (i, j, get(i, j), get(j, i)))
        .filter(|(_, _, a, b)| a != b)
        .max_by(|x, y| (x.2 - x.3).abs().total_cmp(&(y.2 - y.3).abs()))
        .map(|(i, j, a, b)| (i + 1, j + 1, a, b))
}

/// A JSON value's kind and text, as serde would describe it.
fn describe(v: &Value) -> String {
    match v {
        Value::Null => "null".into(),
        Value::Bool(b) => format!("boolean `{b}`"),
        Value::Number(x) => format!("number `{x}`"),
        Value::String(s) => format!("string {s:?}"),
        Value::Array(_) | Value::Object(_) => v.to_string(),
    }
}
