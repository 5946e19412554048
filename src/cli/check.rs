//! `hbal check`: validate a scene (parse it and build its harmonic-balance system) without
//! solving, and print a one-line summary.

use super::{load, Failure};
use std::path::Path;

pub(crate) fn check(path: &Path) -> Result<u8, Failure> {
    let scene = load(path, &super::SolverArgs::default())?;
    hbal::analysis::check(&scene).map_err(|e| super::failure(e, &scene.file))?;
    if !scene.operating_point {
        say!(
            "{}: ok ({} DOF(s), {} element(s); no operating point: without `fundamental` and \
             `harmonics` the scene is for hbal modes and check)",
            scene.file,
            scene.model.n_dofs(),
            scene.model.elements().len(),
        );
    } else if let Some(plan) = &scene.torus {
        let bases: Vec<String> = (0..plan.bases.len())
            .map(|b| {
                format!(
                    "{} (order {}, cap {}, grid {})",
                    plan.bases.names()[b],
                    super::speed_text(plan.bases.ratios()[b]),
                    plan.caps[b],
                    plan.samples[b]
                )
            })
            .collect();
        say!(
            "{}: ok ({} DOF(s), {} element(s), on several base frequencies: {}; {} lines, {:?}; {})",
            scene.file,
            scene.model.n_dofs(),
            scene.model.elements().len(),
            bases.join(", "),
            plan.index_set().map_or(0, |s| s.len()),
            plan.truncation,
            plan.why
        );
    } else {
        say!(
        "{}: ok ({} DOF(s), {} element(s), Ω = {:.6} rad/s (order {} of the {} speed), H = {}, \
         N = {}, solver {})",
        scene.file,
        scene.model.n_dofs(),
        scene.model.elements().len(),
        scene.basis.omega(),
        scene.fundamental_order,
        scene.speed_unit,
        scene.basis.harmonics(),
        scene.basis.samples(),
        scene.method.name()
        );
    }
    if let Some(nf) = hbal::analysis::linear_frequencies(&scene) {
        say!("  {}", frequencies(&nf));
    }
    Ok(0)
}

/// `natural frequencies (Hz): 0 (1 rigid), 89.0983, ...`: the first 8 elastic ones.
fn frequencies(nf: &hbal::report::NaturalFrequencies) -> String {
    const SHOWN: usize = 8;
    let elastic: Vec<String> = nf.mean[nf.rigid..]
        .iter()
        .take(SHOWN)
        .map(|f| format!("{f:.6}"))
        .collect();
    let more = nf.mean.len().saturating_sub(nf.rigid + SHOWN);
    let mut parts = Vec::new();
    if nf.rigid > 0 {
        parts.push(format!("0 ({} rigid)", nf.rigid));
    }
    parts.extend(elastic);
    if more > 0 {
        parts.push(format!("... ({more} more: hbal modes)"));
    }
    format!("natural frequencies (Hz): {}", parts.join(", "))
}
