//! `hbal solve`: solve one scene with its (or the given) solver, print a summary or one JSON
//! object, and optionally write harmonics.csv, time_series.csv and SVG plots.

use super::{load, Failure};
use anyhow::Context;
use hbal::report::{line_plot, Axis, Series};
use hbal::{HarmonicBalance, Solution};
use serde_json::json;
use std::path::Path;
use std::time::Instant;

pub(crate) fn solve(
    path: &Path,
    method: Option<&str>,
    harmonics: Option<usize>,
    as_json: bool,
    out: Option<&Path>,
) -> Result<u8, Failure> {
    let scene = load(path, method, harmonics)?;
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--out: cannot create {}", dir.display()))?;
    }
    let hb = HarmonicBalance::new(&scene.model, scene.basis).with_context(|| scene.file.clone())?;
    let mut ws = hb.workspace();
    let start = Instant::now();
    let sol = scene.method.solve(&hb, None, &mut ws)?;
    let solve_seconds = start.elapsed().as_secs_f64();
    let dofs: Vec<_> = sol
        .dof_names()
        .iter()
        .enumerate()
        .map(|(i, name)| {
            json!({
                "name": name,
                "max_abs": sol.max_abs(i),
                "harmonics": (0..=sol.basis().harmonics()).map(|k| {
                    let (c, s) = sol.cos_sin(i, k);
                    json!({"order": k, "cos": c, "sin": s})
                }).collect::<Vec<_>>(),
            })
        })
        .collect();
    if as_json {
        let doc = json!({
            "converged": sol.is_converged(),
            "termination": sol.termination.to_string(),
            "method": scene.method.name(),
            "iterations": sol.stats.iterations,
            "residual": sol.residual(),
            "fundamental_rad_s": sol.basis().omega(),
            "harmonics": sol.basis().harmonics(),
            "samples": sol.basis().samples(),
            "solve_seconds": solve_seconds,
            "dofs": dofs,
            "history": sol.history,
        });
        say!("{doc}");
    } else {
        say!(
            "{}: {} ({}) after {} iteration{}, relative residual {:.2e}, solve {:.3} ms",
            scene.file,
            sol.termination,
            scene.method.name(),
            sol.stats.iterations,
            if sol.stats.iterations == 1 { "" } else { "s" },
            sol.residual(),
            solve_seconds * 1e3
        );
        say!(
            "  fundamental {:.6} rad/s, H = {}, N = {}, truncation estimate {:.1e}",
            sol.basis().omega(),
            sol.basis().harmonics(),
            sol.basis().samples(),
            sol.truncation_estimate()
        );
        for (i, name) in sol.dof_names().iter().enumerate() {
            say!("  max |q| {name}: {:.6e}", sol.max_abs(i));
        }
    }
    if let Some(dir) = out {
        write_outputs(dir, &sol)?;
        if !as_json {
            say!(
                "  wrote harmonics.csv, time_series.csv, time_series.svg, spectrum.svg to {}",
                dir.display()
            );
        }
    }
    Ok(if sol.is_converged() { 0 } else { 1 })
}

fn write_outputs(dir: &Path, sol: &Solution) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let h = sol.basis().harmonics();
    let mut csv = String::from("dof,order,cos,sin\n");
    for (i, name) in sol.dof_names().iter().enumerate() {
        for k in 0..=h {
            let (c, s) = sol.cos_sin(i, k);
            csv.push_str(&format!("{name},{k},{c:e},{s:e}\n"));
        }
    }
    std::fs::write(dir.join("harmonics.csv"), csv)?;
    let points = sol.basis().samples().max(256);
    let period = sol.basis().period();
    let series: Vec<Vec<f64>> = (0..sol.dof_names().len())
        .map(|i| sol.time_series(i, points))
        .collect();
    let mut csv = String::from("t,theta");
    for name in sol.dof_names() {
        csv.push_str(&format!(",{name}"));
    }
    csv.push('\n');
    for j in 0..points {
        let frac = j as f64 / points as f64;
        csv.push_str(&format!(
            "{:e},{:e}",
            frac * period,
            frac * std::f64::consts::TAU
        ));
        for s in &series {
            csv.push_str(&format!(",{:e}", s[j]));
        }
        csv.push('\n');
    }
    std::fs::write(dir.join("time_series.csv"), csv)?;
    let lines: Vec<Series> = sol
        .dof_names()
        .iter()
        .zip(&series)
        .map(|(name, s)| {
            Series::line(
                name.clone(),
                s.iter()
                    .enumerate()
                    .map(|(j, v)| (j as f64 / points as f64 * period, *v))
                    .collect(),
            )
        })
        .collect();
    line_plot(
        &dir.join("time_series.svg"),
        "Periodic solution over one period",
        &Axis::linear("t (s)"),
        &Axis::linear("q"),
        &lines,
    )
    .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    let spectra: Vec<Series> = sol
        .dof_names()
        .iter()
        .enumerate()
        .map(|(i, name)| {
            Series::markers(
                name.clone(),
                (1..=h)
                    .map(|k| (k as f64, sol.harmonic(i, k).norm()))
                    .collect(),
            )
        })
        .collect();
    if h > 0 {
        line_plot(
            &dir.join("spectrum.svg"),
            "Amplitude spectrum (static part omitted)",
            &Axis::linear("harmonic order"),
            &Axis::log("amplitude"),
            &spectra,
        )
        .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    }
    Ok(())
}
