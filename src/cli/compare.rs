//! `hbal compare`: run every solver (or the one of `--method`) and the time-domain reference on
//! one scene, and print a table (or one JSON object) of results, timings and errors against the
//! time domain; with automatic harmonics every method runs at the H they choose.

use super::{load, Failure, SolverArgs};
use anyhow::Context;
use hbal::compare::model_relative_error;
use hbal::report::{line_plot, Axis, Series};
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, Method};
use serde_json::json;
use std::path::Path;
use std::time::Instant;

pub(crate) fn compare(
    path: &Path,
    args: &SolverArgs,
    as_json: bool,
    out: Option<&Path>,
) -> Result<u8, Failure> {
    let scene = load(path, args)?;
    if let Some(dir) = out {
        super::prepare_out(dir)?;
    }
    let names: Vec<&str> = match &args.method {
        Some(_) => vec![scene.method.name()],
        // Every method that applies: the exact piecewise solution only to linear scenes with
        // piecewise-constant coefficients.
        None => hbal::scene::METHODS
            .iter()
            .copied()
            .filter(|&m| {
                m != "piecewise_exact" || hbal::solve::PiecewiseExact::check(&scene.model).is_ok()
            })
            .collect(),
    };
    // Automatic harmonics: every solver and the comparison at the H they choose.
    let mut basis = scene.basis;
    if let Some(auto) = scene.auto {
        let a = hbal::solve::solve_auto(&scene.model, basis, &scene.method, auto)
            .map_err(|e| super::failure(e, &scene.file))?;
        basis = *a.solution.basis();
        eprintln!(
            "note: harmonics: auto, tolerance {:.0e}{}: every method at H = {} (error estimate {:.1e}{})",
            auto.tolerance,
            auto.control.pick("", " on the harmonics 0..H"),
            basis.harmonics(),
            auto.control.of(&a.estimate),
            if a.capped { ", above the tolerance at the cap" } else { "" }
        );
    }
    let hb = HarmonicBalance::with_formulation(&scene.model, basis, args.formulation)
        .with_context(|| scene.file.clone())?;
    let h = basis.harmonics();
    let n = scene.model.n_dofs();
    let mut solutions = Vec::new();
    for name in names {
        let method: Method = args.method_named(&scene, name)?;
        let mut ws = hb.workspace();
        let start = Instant::now();
        let sol = method
            .solve(&hb, None, &mut ws)
            .map_err(|e| super::failure(e, &scene.file))?;
        solutions.push((name, start.elapsed().as_secs_f64(), sol));
    }
    // The time-domain reference starts on the first converged HB orbit (from rest if none):
    // a gear pair with backlash can have coexisting orbits, and a run from rest may find
    // another one. Its error then measures the HB orbit, and grows if that orbit is unstable.
    let start_state = solutions
        .iter()
        .find(|s| s.2.is_converged())
        .map(|(_, _, sol)| {
            let q = (0..n).map(|i| sol.displacement(i, 0.0)).collect::<Vec<_>>();
            let v = (0..n).map(|i| sol.velocity(i, 0.0)).collect::<Vec<_>>();
            (q, v)
        });
    let from_orbit = start_state.is_some();
    let td = TimeSimulation {
        rtol: 1e-10,
        steady_tolerance: 1e-8,
        // Its harmonics come from samples: 1024 put 8e-7 into the two-shaft model's at
        // 600 rpm (the ringing of its stiffness jumps near harmonic 77), 4096 3e-9.
        samples: (4 * h + 4).next_power_of_two().max(4096),
        initial: start_state,
        ..TimeSimulation::default()
    }
    .run(&scene.model, basis.omega())
    .with_context(|| format!("{}: time-domain reference", scene.file))?;
    let mut rows = Vec::new();
    let mut histories = Vec::new();
    let mut any_converged = false;
    let samples = td.samples.first().map_or(0, |s| s.len());
    for (name, seconds, sol) in &solutions {
        let error = model_relative_error(&scene.model, sol.harmonics(), &td.harmonics, h);
        // The exact method by its closed form in time, with the ringing above H.
        let series = (*name == "piecewise_exact")
            .then(|| {
                hbal::solve::PiecewiseExact::new()
                    .solve_exact(&scene.model, &basis)
                    .and_then(|e| e.series_harmonics(samples))
                    .ok()
            })
            .flatten();
        // Per quantity, against the time domain's samples (all its harmonics, not only 0..H).
        let worst = (basis.subharmonic() == 1)
            .then(|| {
                hbal::compare::quantity_errors(
                    &scene.model,
                    &basis,
                    series.as_deref().unwrap_or(sol.harmonics()),
                    &td.harmonics,
                    samples,
                )
                .ok()
            })
            .flatten()
            .and_then(|q| hbal::compare::quantities::worst(&q, |_| true));
        any_converged |= sol.is_converged();
        histories.push(Series::line(
            *name,
            sol.history
                .iter()
                .enumerate()
                .map(|(i, r)| (i as f64, *r))
                .collect(),
        ));
        rows.push(json!({
            "method": name,
            "converged": sol.is_converged(),
            "termination": sol.termination.to_string(),
            "iterations": sol.stats.iterations,
            "residual": sol.residual(),
            "solve_seconds": seconds,
            "error_vs_time_domain": error,
            "worst_quantity_vs_time_domain": super::quantity_report::quantity_json(&scene.model, worst),
        }));
    }
    let td_json = json!({
        "started_on_hb_orbit": from_orbit,
        "converged": td.converged,
        "stop": format!("{:?}", td.stop),
        "periods": td.periods,
        "steps": td.steps,
        "seconds": td.wall_time.as_secs_f64(),
    });
    if as_json {
        say!(
            "{}",
            json!({"scene": scene.file, "harmonics": h, "samples": basis.samples(), "time_domain": td_json, "methods": rows})
        );
    } else {
        say!(
            "{}: time domain (from {}) {:?} after {} periods, {} steps, {:.3} ms",
            scene.file,
            if from_orbit { "the HB orbit" } else { "rest" },
            td.stop,
            td.periods,
            td.steps,
            td.wall_time.as_secs_f64() * 1e3
        );
        say!("| method | result | iterations | wall | error vs time domain | worst quantity (dynamic part, of its range) |");
        say!("|---|---|---:|---:|---:|---|");
        for r in &rows {
            let q = &r["worst_quantity_vs_time_domain"];
            say!(
                "| {} | {} | {} | {:.3} ms | {:.2e} | {} |",
                r["method"].as_str().unwrap_or(""),
                r["termination"].as_str().unwrap_or(""),
                r["iterations"],
                r["solve_seconds"].as_f64().unwrap_or(f64::NAN) * 1e3,
                r["error_vs_time_domain"].as_f64().unwrap_or(f64::NAN),
                match q["error"].as_f64() {
                    Some(e) => format!("{} {e:.2e}", q["name"].as_str().unwrap_or("")),
                    None => "–".into(),
                }
            );
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        line_plot(
            &dir.join("residual_histories.svg"),
            "Residual histories",
            &Axis::linear("iteration"),
            &Axis::log("relative residual"),
            &histories,
        )
        .unwrap_or_else(super::plot_warning);
    }
    if !any_converged {
        eprintln!(
            "error: {}: no method converged (the table and the time-domain reference stand)",
            scene.file
        );
    }
    Ok(if any_converged { 0 } else { 1 })
}
