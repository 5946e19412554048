//! Which outputs a sweep reports: the DOFs whose harmonics are written in full (`--dofs`) and
//! the element or DOF its order-cut plot and waterfall show (`--output`), chosen and checked
//! before any work.
//!
//! A discretised shaft has hundreds of DOFs whose harmonics say little one by one: the
//! drivetrain of 1000 DOFs wrote a 448 MB branch.csv and a thousand plots for a 604-point
//! run-up. Above [`ALL_DOFS_UP_TO`] DOFs the default is the DOFs where the physics is: those an
//! element (mesh, contact, clutch, spring) or a load acts on. `max |q|` of every DOF is always
//! kept.

use crate::scene::Scene;
use crate::{Error, Model, Result};

/// Up to this many DOFs every one is reported by default.
pub const ALL_DOFS_UP_TO: usize = 64;

/// The output a sweep's order-cut plot and waterfall show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shown {
    /// An element's coordinate (a gear stage's transmission error in µm or µrad).
    Element(usize),
    /// A DOF.
    Dof(usize),
    /// The DOF with the largest dynamic amplitude along the branch.
    LargestDof,
}

/// The output named `name` (an element, else a DOF), or the default: the first gear stage,
/// else the DOF that moves most.
///
/// # Errors
/// An unknown name ([`Error::InvalidOptions`] of `--output`, listing the names).
pub fn shown_output(scene: &Scene, name: Option<&str>) -> Result<Shown> {
    let elements = scene.model.elements();
    let Some(name) = name else {
        return Ok(elements
            .iter()
            .position(|e| e.gear_stage().is_some())
            .map_or(Shown::LargestDof, Shown::Element));
    };
    if let Some(i) = elements.iter().position(|e| e.name() == name) {
        return Ok(Shown::Element(i));
    }
    if let Some(i) = scene.model.dof_index(name) {
        return Ok(Shown::Dof(i));
    }
    let list = |names: Vec<&str>| {
        let more = names.len().saturating_sub(12);
        let mut s = names.into_iter().take(12).collect::<Vec<_>>().join(", ");
        if more > 0 {
            s.push_str(&format!(" and {more} more"));
        }
        s
    };
    Err(Error::InvalidOptions {
        option: "--output".into(),
        reason: format!(
            "`{name}` is neither an element ({}) nor a DOF ({})",
            list(elements.iter().map(|e| e.name()).collect()),
            list(scene.model.dof_names().iter().map(String::as_str).collect()),
        ),
    })
}

/// The DOFs to report (indices in the model's order) from `spec`: `all`, a comma-separated
/// list of DOF names (or one name that holds a comma), or by default every DOF up to
/// [`ALL_DOFS_UP_TO`], else those of the elements and loads.
///
/// # Errors
/// An empty or unknown name ([`Error::InvalidOptions`] of `--dofs`).
pub fn reported_dofs(model: &Model, spec: Option<&str>) -> Result<Vec<usize>> {
    let n = model.n_dofs();
    let spec = spec.map(str::trim);
    // A whole list that is one DOF's name (a name may hold a comma).
    if let Some(i) = spec.and_then(|s| model.dof_index(s)) {
        if spec != Some("all") {
            return Ok(vec![i]);
        }
    }
    let mut chosen = match spec {
        Some("all") => return Ok((0..n).collect()),
        None if n <= ALL_DOFS_UP_TO => return Ok((0..n).collect()),
        None => {
            let mut touched: Vec<usize> = model
                .elements()
                .iter()
                .flat_map(|e| {
                    e.weights()
                        .iter()
                        .filter(|(_, w)| *w != 0.0)
                        .map(|&(i, _)| i)
                })
                .chain(model.loaded_dofs())
                .collect();
            if touched.is_empty() {
                touched = (0..n.min(ALL_DOFS_UP_TO)).collect();
            }
            touched
        }
        Some(list) => list
            .split(',')
            .map(|name| named_dof(model, list, name.trim()))
            .collect::<Result<Vec<usize>>>()?,
    };
    chosen.sort_unstable();
    chosen.dedup();
    Ok(chosen)
}

/// The index of the DOF `name` of the `--dofs` list `list`.
fn named_dof(model: &Model, list: &str, name: &str) -> Result<usize> {
    let bad = |reason: String| Error::InvalidOptions {
        option: "--dofs".into(),
        reason,
    };
    if name.is_empty() {
        return Err(bad(format!(
            "has an empty name in `{list}` (DOF names separated by commas, or `all`)"
        )));
    }
    model.dof_index(name).ok_or_else(|| {
        let names = model.dof_names();
        let shown: Vec<&str> = names.iter().take(8).map(String::as_str).collect();
        bad(format!(
            "names `{name}`, but the model has no DOF named `{name}` (its {} DOFs: {}{})",
            names.len(),
            shown.join(", "),
            if names.len() > shown.len() {
                ", ..."
            } else {
                ""
            }
        ))
    })
}
