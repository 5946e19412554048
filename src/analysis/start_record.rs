//! Harmonics to start a solve or a sweep from, read from a previous solve's record (what
//! `hbal solve --json` prints and a binding's result holds): DOFs are matched by name,
//! harmonics above the scene's H are dropped and missing ones are zero. One reading for every
//! front end (the command line's `--start FILE`, the Python package's `guess=`).

use crate::scene::Scene;
use num_complex::Complex64;
use serde_json::Value;

/// The initial guess read from a solve's record.
#[derive(Debug, Clone, PartialEq)]
pub struct StartRecord {
    /// Harmonic-major `Q[k * n + i]` on the scene's H.
    pub harmonics: Vec<Complex64>,
    /// The fundamental the record was computed at (rad/s), if it says.
    pub omega: Option<f64>,
    /// Harmonic orders in the record above the scene's H (dropped).
    pub dropped_orders: usize,
}

/// Reads the record `doc` of a solve for `scene`; the error says what does not fit.
///
/// ```
/// # use hbal::scene::Scene;
/// # let scene = Scene::load(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/duffing.toml"))).unwrap();
/// let record = serde_json::json!({"dofs": [{"name": "x", "harmonics": [{"order": 1, "cos": 0.2, "sin": 0.0}]}]});
/// let start = hbal::analysis::start_from_record(&record, &scene).unwrap();
/// assert_eq!(start.harmonics[1].re, 0.2);
/// let other = serde_json::json!({"dofs": [{"name": "y", "harmonics": [{"order": 1, "cos": 0.2, "sin": 0.0}]}]});
/// assert!(hbal::analysis::start_from_record(&other, &scene).unwrap_err().contains("DOF `y` is not in the scene"));
/// ```
pub fn start_from_record(doc: &Value, scene: &Scene) -> Result<StartRecord, String> {
    let Some(dofs) = doc.get("dofs").and_then(Value::as_array) else {
        return Err("no `dofs` list".into());
    };
    let omega = match doc.get("fundamental_rad_s") {
        None | Some(Value::Null) => None,
        Some(v) => match v.as_f64() {
            Some(w) if w.is_finite() && w > 0.0 => Some(w),
            _ => return Err(format!("`fundamental_rad_s` must be a number > 0, got {v}")),
        },
    };
    let names = scene.model.dof_names();
    let n = names.len();
    let h = scene.basis.harmonics();
    let mut harmonics = vec![Complex64::default(); (h + 1) * n];
    let mut seen = vec![false; n];
    let mut dropped = std::collections::BTreeSet::new();
    for (j, dof) in dofs.iter().enumerate() {
        let Some(name) = dof.get("name").and_then(Value::as_str) else {
            return Err(format!("dofs[{j}] has no `name`"));
        };
        let Some(i) = names.iter().position(|d| d == name) else {
            return Err(format!(
                "DOF `{name}` is not in the scene {} (its DOFs: {})",
                scene.file,
                names.join(", ")
            ));
        };
        if seen[i] {
            return Err(format!("DOF `{name}` appears twice"));
        }
        seen[i] = true;
        let list = match dof.get("harmonics").and_then(Value::as_array) {
            Some(l) if !l.is_empty() => l,
            _ => return Err(format!("dofs[{j}] (`{name}`) has no `harmonics`")),
        };
        for (m, entry) in list.iter().enumerate() {
            let at = format!("dofs[{j}].harmonics[{m}]");
            let (order, q) = entry_of(entry, &at)?;
            if order > h {
                dropped.insert(order);
            } else {
                harmonics[order * n + i] = q;
            }
        }
    }
    let missing: Vec<&str> = names
        .iter()
        .zip(&seen)
        .filter(|(_, s)| !**s)
        .map(|(d, _)| d.as_str())
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "no harmonics for DOF(s) {} of the scene {}",
            missing.join(", "),
            scene.file
        ));
    }
    Ok(StartRecord {
        harmonics,
        omega,
        dropped_orders: dropped.len(),
    })
}

/// The order and the complex harmonic of one entry `{order, cos, sin}` (`at` names it).
fn entry_of(entry: &Value, at: &str) -> Result<(usize, Complex64), String> {
    let order = entry
        .get("order")
        .and_then(Value::as_u64)
        .ok_or_else(|| format!("{at}: `order` must be an integer >= 0"))? as usize;
    let number = |key: &str| -> Result<f64, String> {
        match entry.get(key).and_then(Value::as_f64) {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(format!("{at}: `{key}` must be a finite number")),
        }
    };
    let (c, s) = (number("cos")?, number("sin")?);
    // The static part is real: a sine of order 0 is zero.
    let s = if order == 0 { 0.0 } else { s };
    Ok((order, crate::harmonic::from_cos_sin(c, s)))
}
