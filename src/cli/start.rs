//! `--start FILE`: a previous `hbal solve --json` result as the initial guess of `solve` or
//! `sweep`. DOFs are matched by name; harmonics above the scene's H are dropped and missing
//! ones are zero. A file that does not fit the scene is bad input (exit code 2).

use super::Failure;
use hbal::scene::Scene;
use num_complex::Complex64;
use serde_json::Value;
use std::path::Path;

/// The initial guess read from a start file.
pub(crate) struct Start {
    /// Harmonic-major `Q[k * n + i]` on the scene's H.
    pub(crate) harmonics: Vec<Complex64>,
    /// The fundamental the file was computed at (rad/s), if it says.
    pub(crate) omega: Option<f64>,
    /// Harmonic orders in the file above the scene's H (dropped).
    pub(crate) dropped_orders: usize,
}

/// Reads `path` (the JSON of `hbal solve --json`) for `scene`.
pub(crate) fn read(path: &Path, scene: &Scene) -> Result<Start, Failure> {
    let file = path.display().to_string();
    let bad = |msg: String| -> Failure {
        anyhow::anyhow!("--start {file}: {msg} (expected the output of `hbal solve --json`)").into()
    };
    let text = hbal::scene::bounded_read::read_text(path)
        .map_err(|e| Failure::from(anyhow::anyhow!("--start {file}: cannot read the file: {e}")))?;
    let doc: Value =
        serde_json::from_str(&text).map_err(|e| bad(format!("not a JSON object: {e}")))?;
    let Some(dofs) = doc.get("dofs").and_then(Value::as_array) else {
        return Err(bad("no `dofs` list".into()));
    };
    let omega = match doc.get("fundamental_rad_s") {
        None | Some(Value::Null) => None,
        Some(v) => match v.as_f64() {
            Some(w) if w.is_finite() && w > 0.0 => Some(w),
            _ => {
                return Err(bad(format!(
                    "`fundamental_rad_s` must be a number > 0, got {v}"
                )))
            }
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
            return Err(bad(format!("dofs[{j}] has no `name`")));
        };
        let Some(i) = names.iter().position(|d| d == name) else {
            return Err(bad(format!(
                "DOF `{name}` is not in the scene {} (its DOFs: {})",
                scene.file,
                names.join(", ")
            )));
        };
        if seen[i] {
            return Err(bad(format!("DOF `{name}` appears twice")));
        }
        seen[i] = true;
        let list = match dof.get("harmonics").and_then(Value::as_array) {
            Some(l) if !l.is_empty() => l,
            _ => return Err(bad(format!("dofs[{j}] (`{name}`) has no `harmonics`"))),
        };
        for (m, entry) in list.iter().enumerate() {
            let at = format!("dofs[{j}].harmonics[{m}]");
            let order = entry
                .get("order")
                .and_then(Value::as_u64)
                .ok_or_else(|| bad(format!("{at}: `order` must be an integer >= 0")))?
                as usize;
            let number = |key: &str| -> Result<f64, Failure> {
                match entry.get(key).and_then(Value::as_f64) {
                    Some(v) if v.is_finite() => Ok(v),
                    _ => Err(bad(format!("{at}: `{key}` must be a finite number"))),
                }
            };
            let (c, s) = (number("cos")?, number("sin")?);
            if order > h {
                dropped.insert(order);
                continue;
            }
            // The static part is real: a sine of order 0 is zero.
            let s = if order == 0 { 0.0 } else { s };
            harmonics[order * n + i] = hbal::harmonic::from_cos_sin(c, s);
        }
    }
    let missing: Vec<&str> = names
        .iter()
        .zip(&seen)
        .filter(|(_, s)| !**s)
        .map(|(d, _)| d.as_str())
        .collect();
    if !missing.is_empty() {
        return Err(bad(format!(
            "no harmonics for DOF(s) {} of the scene {}",
            missing.join(", "),
            scene.file
        )));
    }
    Ok(Start {
        harmonics,
        omega,
        dropped_orders: dropped.len(),
    })
}
