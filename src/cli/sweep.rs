//! `hbal sweep` (without `--parameter`): follow the frequency response from `--from` to `--to`
//! through turning points by arclength continuation, with stability, and optionally write
//! branch.csv and one frequency-response SVG per DOF.

use super::{load, Failure};
use anyhow::Context;
use hbal::HarmonicBasis;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

pub(crate) fn sweep(
    path: &Path,
    from: f64,
    to: f64,
    as_json: bool,
    out: Option<&Path>,
    max_step: f64,
) -> Result<u8, Failure> {
    use hbal::continuation::{BranchStop, Continuation};
    let scene = load(path, None, None)?;
    let unit = scene.speed_unit;
    for (name, v) in [("--from", from), ("--to", to)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(
                anyhow::anyhow!("{name} must be a finite speed > 0 ({unit}), got {v}").into(),
            );
        }
    }
    if !(max_step.is_finite() && max_step > 0.0) {
        return Err(anyhow::anyhow!("--max-step must be finite and > 0, got {max_step}").into());
    }
    let per = scene.omega_per_speed;
    let basis = HarmonicBasis::new(from * per, scene.basis.harmonics())?
        .with_samples(scene.basis.samples())
        .with_context(|| scene.file.clone())?;
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    if as_json {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let start = Instant::now();
    let continuation = Continuation {
        max_step,
        ..Continuation::default()
    };
    let branch = continuation
        .run(&scene.model, basis, to * per, |f| {
            bar.set_position((f * 1000.0) as u64);
        })
        .with_context(|| scene.file.clone())?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let speed = |omega: f64| omega / per;
    let n = scene.model.n_dofs();
    if as_json {
        let points: Vec<_> = branch
            .points
            .iter()
            .map(|p| {
                json!({
                    "speed": speed(p.omega),
                    "omega_rad_s": p.omega,
                    "stable": p.stable(),
                    "fold": p.fold,
                    "bifurcation": p.bifurcation.map(|b| format!("{b:?}")),
                    "max_abs": p.max_abs,
                    "multipliers_abs": p.floquet.as_ref().map(|f| f.multipliers.iter().map(|m| m.norm()).collect::<Vec<_>>()),
                    "harmonics": (0..n).map(|i| (0..=branch.harmonics).map(|k| {
                        let (c, s) = hbal::harmonic::cos_sin(p.harmonics[k * n + i]);
                        json!({"order": k, "cos": c, "sin": s})
                    }).collect::<Vec<_>>()).collect::<Vec<_>>(),
                })
            })
            .collect();
        say!(
            "{}",
            json!({
                "scene": scene.file,
                "unit": unit,
                "stop": branch.stop.to_string(),
                "reached": branch.stop == BranchStop::Reached,
                "points": points,
                "folds": branch.folds(),
                "seconds": seconds,
                "dofs": branch.dofs,
            })
        );
    } else {
        let unstable = branch
            .points
            .iter()
            .filter(|p| p.stable() == Some(false))
            .count();
        say!(
            "{}: {} points from {from} to {to} {unit} in {:.1} ms: {}; {} folds, {} unstable points",
            scene.file,
            branch.points.len(),
            seconds * 1e3,
            branch.stop,
            branch.folds(),
            unstable
        );
        for p in branch
            .points
            .iter()
            .filter(|p| p.fold || p.bifurcation.is_some())
        {
            let what = match (p.fold, p.bifurcation) {
                (true, Some(b)) => format!("fold, stability change ({b:?})"),
                (true, None) => "fold".to_string(),
                (false, Some(b)) => format!("stability change ({b:?})"),
                _ => unreachable!("filtered"),
            };
            say!(
                "  {what} at {:.6} {unit}, max |q| = {:.6e}",
                speed(p.omega),
                p.max_abs[0]
            );
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(
            dir.join("branch.csv"),
            hbal::report::branch_csv(&branch, unit, speed),
        )?;
        if branch.points.len() >= 2 {
            for (i, dof) in branch.dofs.iter().enumerate() {
                hbal::report::branch_plot(
                    &dir.join(format!("frequency_response_{dof}.svg")),
                    &branch,
                    i,
                    &format!("Frequency response of {dof}"),
                    &format!("speed ({unit})"),
                    speed,
                )
                .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
            }
        }
    }
    Ok(if branch.stop == BranchStop::Reached {
        0
    } else {
        1
    })
}
