//! Which DOFs a sweep reports in full, `--dofs`: their harmonics in branch.csv and in the JSON
//! points, their order cuts in order_cuts.csv, and a response plot each. `max |q|` of every
//! DOF is always written.
//!
//! A discretised shaft has hundreds of DOFs whose harmonics say little one by one: the
//! drivetrain of 1000 DOFs wrote a 448 MB branch.csv and a thousand plots for a 604-point
//! run-up. Above [`ALL_UP_TO`] DOFs the default is the DOFs where the physics is: those an
//! element (mesh, contact, clutch, spring) or a load acts on.

use hbal::Model;

/// Up to this many DOFs every one is reported by default.
pub(crate) const ALL_UP_TO: usize = 64;

/// The DOFs to report (indices in the model's order) from `--dofs`: `all`, a comma-separated
/// list of DOF names (or one name that holds a comma), or by default every DOF up to
/// [`ALL_UP_TO`], else those of the elements and loads.
pub(crate) fn reported_dofs(model: &Model, spec: Option<&str>) -> anyhow::Result<Vec<usize>> {
    let names = model.dof_names();
    let n = names.len();
    let spec = spec.map(str::trim);
    // A whole list that is one DOF's name (a name may hold a comma).
    if let Some(i) = spec.and_then(|s| model.dof_index(s)) {
        if spec != Some("all") {
            return Ok(vec![i]);
        }
    }
    let mut chosen = match spec {
        Some("all") => return Ok((0..n).collect()),
        None if n <= ALL_UP_TO => return Ok((0..n).collect()),
        None => {
            let mut touched: Vec<usize> = model
                .elements()
                .iter()
                .flat_map(|e| e.weights().iter().filter(|(_, w)| *w != 0.0).map(|&(i, _)| i))
                .chain(model.loaded_dofs())
                .collect();
            if touched.is_empty() {
                touched = (0..n.min(ALL_UP_TO)).collect();
            }
            touched
        }
        Some(list) => list
            .split(',')
            .map(|name| {
                let name = name.trim();
                if name.is_empty() {
                    anyhow::bail!("--dofs: an empty name in `{list}` (DOF names separated by commas, or `all`)");
                }
                model.dof_index(name).ok_or_else(|| {
                    let shown: Vec<&str> = names.iter().take(8).map(String::as_str).collect();
                    anyhow::anyhow!(
                        "--dofs: the model has no DOF named `{name}` (its {n} DOFs: {}{})",
                        shown.join(", "),
                        if n > shown.len() { ", ..." } else { "" }
                    )
                })
            })
            .collect::<anyhow::Result<Vec<usize>>>()?,
    };
    chosen.sort_unstable();
    chosen.dedup();
    Ok(chosen)
}

/// What the summary says when not every DOF is reported.
pub(crate) fn note(model: &Model, reported: &[usize]) -> Option<String> {
    let n = model.n_dofs();
    (reported.len() < n).then(|| {
        format!(
            "harmonics and response plots of {} of {n} DOFs (--dofs NAME,... or --dofs all for more; max |q| of all)",
            reported.len()
        )
    })
}
