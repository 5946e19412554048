//! `hbal sweep --parameter <field>`: a warm-started sweep of one numeric scene field over
//! `--points` values (does not follow folds), with stability (unless `--no-stability`), on the
//! scene's basis or the one of `--harmonics`/`--samples` (automatic harmonics: H and N chosen at
//! the first value and kept), and optionally branch.csv and one parameter-response SVG per DOF.

use super::{basis_with, Failure, SolverArgs};
use hbal::scene::Scene;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Options of a `--parameter` sweep.
pub(crate) struct ParameterSweep<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: f64,
    pub(crate) points: usize,
    pub(crate) solver: &'a SolverArgs,
    pub(crate) start: Option<&'a Path>,
    pub(crate) stability: bool,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
    /// `--dofs` ([`hbal::analysis::reported_dofs`]).
    pub(crate) dofs: Option<&'a str>,
}

pub(crate) fn parameter_sweep(
    path: &Path,
    name: &str,
    opts: ParameterSweep,
) -> Result<u8, Failure> {
    use hbal::continuation::{parameter_sweep, BranchStop};
    let (to, points, as_json, out) = (opts.to, opts.points, opts.json, opts.out);
    let Some(from) = opts.from else {
        return Err(anyhow::anyhow!("--parameter needs --from").into());
    };
    // A parameter sweep is warm-started Newton from the linear solution.
    for (flag, given) in [
        ("--start", opts.start.is_some()),
        ("--method", opts.solver.method.is_some()),
        ("--tolerance", opts.solver.tolerance.is_some()),
    ] {
        if given {
            return Err(anyhow::anyhow!(
                "{flag} applies to speed sweeps, not to a --parameter sweep"
            )
            .into());
        }
    }
    let file = path.display().to_string();
    let text = hbal::scene::bounded_read::read_text(path)
        .map_err(|e| anyhow::anyhow!("{file}: cannot read the file: {e}"))?;
    let doc = Scene::parse_value(&text, &file)?;
    if !(from.is_finite() && to.is_finite()) || points < 2 {
        return Err(anyhow::anyhow!("--from and --to must be finite and --points >= 2").into());
    }
    // Check the path and the scene once before sweeping.
    let mut probe = doc.clone();
    hbal::scene::set_parameter(&mut probe, name, from)
        .map_err(|e| anyhow::anyhow!("{file}: --parameter {e}"))?;
    let mut probe = Scene::from_value(probe, &file)?;
    let first = basis_with(&probe.basis, opts.solver, &file)?;
    let reported = hbal::analysis::reported_dofs(&probe.model, opts.dofs)?;
    if let Some(dir) = out {
        for dof in probe.model.dof_names() {
            super::file_name_part(dof, "DOF")?;
        }
        super::prepare_out(dir)?;
    }
    let values: Vec<f64> = (0..points)
        .map(|i| from + (to - from) * i as f64 / (points - 1) as f64)
        .collect();
    whole_values(&doc, name, &values, &file)?;
    // Automatic harmonics: H and N chosen at the first value, kept for the others.
    super::auto_with(&mut probe.auto, opts.solver);
    let chosen = match probe.auto {
        Some(auto) => {
            let a = hbal::solve::solve_auto(&probe.model, first, &probe.method, auto)
                .map_err(|e| super::failure(e, &file))?;
            let b = *a.solution.basis();
            eprintln!(
                "note: harmonics: auto, tolerance {:.0e}{}: H = {} (error estimate {:.1e} at {name} = {from}{}), kept for every value and not checked at the others",
                auto.tolerance,
                auto.control.pick("", " on the harmonics 0..H"),
                b.harmonics(),
                auto.control.of(&a.estimate),
                if a.capped { ", above the tolerance at the cap" } else { "" }
            );
            Some(b)
        }
        None => None,
    };
    let bar = super::progress::Progress::new("parameter sweep", as_json);
    let start = Instant::now();
    let branch = parameter_sweep(
        &values,
        |p| {
            let mut d = doc.clone();
            hbal::scene::set_parameter(&mut d, name, p)
                .map_err(|e| hbal::Error::Solver { reason: e })?;
            let scene = Scene::from_value(d, &file).map_err(|e| hbal::Error::Solver {
                reason: e.to_string(),
            })?;
            let mut basis =
                basis_with(&scene.basis, opts.solver, &file).map_err(|e| hbal::Error::Solver {
                    reason: format!("{:#}", e.error),
                })?;
            if let Some(chosen) = &chosen {
                basis = super::basis_like(&basis, chosen)?;
            }
            Ok((scene.model, basis))
        },
        opts.stability
            .then(hbal::stability::FloquetOptions::default),
        opts.solver.formulation,
        |f| bar.set(f),
    )
    .map_err(|e| Failure {
        code: super::exit_code(&e),
        error: anyhow::Error::new(e).context(file.clone()),
    })?;
    bar.finish();
    let seconds = start.elapsed().as_secs_f64();
    if as_json {
        let pts: Vec<_> = branch
            .points
            .iter()
            .map(|p| {
                json!({
                    "parameter": p.parameter,
                    "stable": p.stable(),
                    "bifurcation": p.bifurcation.map(|b| format!("{b:?}")),
                    "max_abs": p.max_abs,
                    "residual": p.residual,
                    "truncation": p.truncation,
                    "multipliers": p.floquet.as_ref().map(super::multipliers_json),
                    "multipliers_abs": p.floquet.as_ref().map(|f| f.multipliers.iter().map(|m| m.norm()).collect::<Vec<_>>()),
                    "neutral": p.floquet.as_ref().map(|f| f.neutral),
                    "orbit_correction": p.floquet.as_ref().map(|f| f.orbit_correction),
                })
            })
            .collect();
        say!(
            "{}",
            json!({"scene": file, "parameter": name, "harmonics": branch.harmonics, "stop": branch.stop.to_string(), "reached": branch.stop == BranchStop::Reached, "seconds": seconds, "dofs": branch.dofs, "points": pts})
        );
    } else {
        say!(
            "{file}: {} values of {name} from {from} to {to} in {:.1} ms: {}",
            branch.points.len(),
            seconds * 1e3,
            branch.stop
        );
        for p in branch.points.iter().filter(|p| p.bifurcation.is_some()) {
            say!(
                "  stability change ({:?}) at {name} = {}",
                p.bifurcation.unwrap_or(hbal::stability::Bifurcation::Fold),
                p.parameter
            );
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(
            dir.join("branch.csv"),
            hbal::report::branch_csv_of_dofs(
                &branch,
                probe.fundamental_order,
                &reported,
                name,
                |p| p,
            ),
        )?;
        if branch.points.len() >= 2 {
            for &i in &reported {
                let dof = &branch.dofs[i];
                hbal::report::branch_plot(
                    &dir.join(format!("parameter_response_{dof}.svg")),
                    &branch,
                    i,
                    &format!("Response of {dof} against {name}"),
                    name,
                    |p| p,
                )
                .unwrap_or_else(super::plot_warning);
            }
        }
    }
    if branch.stop == BranchStop::Reached {
        Ok(0)
    } else {
        eprintln!("error: {file}: the sweep stopped: {}", branch.stop);
        Ok(1)
    }
}

/// A whole-number field (`harmonics.count`, a `teeth`) takes whole values only: refuses the
/// sweep before it starts if one of `values` is not whole and the field does not take it.
fn whole_values(
    doc: &serde_json::Value,
    name: &str,
    values: &[f64],
    file: &str,
) -> Result<(), Failure> {
    let Some((i, x)) = values.iter().enumerate().find(|(_, x)| x.fract() != 0.0) else {
        return Ok(());
    };
    let mut probe = doc.clone();
    hbal::scene::set_parameter(&mut probe, name, *x)
        .map_err(|e| anyhow::anyhow!("{file}: --parameter {e}"))?;
    match Scene::from_value(probe, file) {
        Err(e) if e.message.starts_with("invalid type: floating point") => Err(anyhow::anyhow!(
            "{file}: --parameter {name} takes whole numbers, and value {} ({x}) is not one: \
             choose --from, --to and --points so that every value is whole",
            i + 1
        )
        .into()),
        _ => Ok(()),
    }
}
