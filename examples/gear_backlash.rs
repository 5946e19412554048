//! The gear pair with backlash and time-varying mesh stiffness,
//! `x'' + 2ζ x' + (1 + ε cos Wt) g(x) = Fm + Fa cos Wt` (ζ 0.05, ε 0.2, Fm 0.1, Fa 0.05, b 1),
//! swept over W = 0.4 … 1.6 by pseudo-arclength continuation with Floquet stability: the
//! softening jump, its folds, the no-impact / contact-loss / double-sided-impact regions, and a
//! check against the time domain swept up and down (coexisting solutions must both appear).
//! Then a speed sweep of the two-shaft model.
//!
//! Run: `cargo run --release --example gear_backlash [-- --out DIR]`

mod common;

use hbal::catalog::{GearBacklash, TwoShaft};
use hbal::compare::relative_error;
use hbal::continuation::{Branch, Continuation};
use hbal::report::{branch_csv, branch_plot};
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, HarmonicBasis, Newton};
use std::time::Instant;

const H: usize = 32;

fn regime(branch: &Branch, i: usize, b: f64) -> &'static str {
    let p = &branch.points[i];
    // min x over one period from the harmonics.
    let n = branch.dofs.len();
    let min = (0..512)
        .map(|j| {
            let th = std::f64::consts::TAU * j as f64 / 512.0;
            (0..=branch.harmonics)
                .map(|k| {
                    (p.harmonics[k * n] * num_complex::Complex64::from_polar(1.0, k as f64 * th)).re
                })
                .sum::<f64>()
        })
        .fold(f64::MAX, f64::min);
    if min > b {
        "no impact"
    } else if min >= -b {
        "contact loss"
    } else {
        "double-sided impact"
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = common::out_dir()?;
    let pair = GearBacklash::default();
    let model = pair.model()?;

    let start = Instant::now();
    let branch = Continuation {
        max_step: 0.1,
        ..Continuation::default()
    }
    .run(&model, HarmonicBasis::new(0.4, H)?, 1.6, |_| {})?;
    let wall = start.elapsed();
    println!(
        "Continuation W 0.4 -> 1.6, H = {H}: {} points with Floquet stability in {:.1} ms ({}), {} folds",
        branch.points.len(),
        wall.as_secs_f64() * 1e3,
        branch.stop,
        branch.folds()
    );

    // Regions along the branch.
    println!("\n| from W | to W | regime | stability |");
    println!("|---:|---:|---|---|");
    let mut seg_start = 0;
    for i in 1..=branch.points.len() {
        let key = |j: usize| (regime(&branch, j, pair.b), branch.points[j].stable());
        if i == branch.points.len() || key(i) != key(seg_start) {
            let (r, s) = key(seg_start);
            println!(
                "| {:.4} | {:.4} | {r} | {} |",
                branch.points[seg_start].omega,
                branch.points[i - 1].omega,
                match s {
                    Some(true) => "stable",
                    Some(false) => "unstable",
                    None => "?",
                }
            );
            seg_start = i;
        }
    }
    for p in branch.points.iter().filter(|p| p.fold) {
        println!("fold at W = {:.5}, max x = {:.5}", p.omega, p.max_abs[0]);
    }
    std::fs::write(
        out.join("gear_backlash_branch.csv"),
        branch_csv(&branch, "W", |w| w),
    )?;
    branch_plot(
        &out.join("gear_backlash_frequency_response.svg"),
        &branch,
        0,
        "Gear pair with backlash: frequency response (H = 32)",
        "W (mesh frequency / natural frequency)",
        |w| w,
    )?;

    // Time domain swept up and down, each W starting from the previous end state.
    println!("\nTime domain swept up and down (rtol 1e-9), each orbit against the nearest HB solution at the same W:\n");
    println!("| W | sweep | TD max x | nearest HB: stable? | distance |");
    println!("|---:|---|---:|---|---:|");
    let grid: Vec<f64> = (0..=12).map(|i| 0.4 + 0.1 * i as f64).collect();
    let mut coexisting = 0;
    for (label, order) in [
        ("up", grid.clone()),
        ("down", grid.iter().rev().copied().collect::<Vec<_>>()),
    ] {
        let mut state = (vec![1.1], vec![0.0]);
        let mut max_by_w = Vec::new();
        for &w in &order {
            let td = TimeSimulation {
                rtol: 1e-9,
                steady_tolerance: 1e-8,
                samples: 256,
                initial: Some(state.clone()),
                ..TimeSimulation::default()
            }
            .run(&model, w)?;
            state = (td.end_state[..1].to_vec(), td.end_state[1..].to_vec());
            // HB solutions at this W from the branch points that cross it.
            let hb = HarmonicBalance::new(&model, HarmonicBasis::new(w, H)?)?;
            let mut best: Option<(f64, bool)> = None;
            for pair_pts in branch.points.windows(2) {
                if (pair_pts[0].omega - w) * (pair_pts[1].omega - w) <= 0.0 {
                    let sol = Newton::new().solve_from(
                        &hb,
                        &pair_pts[0].harmonics,
                        &mut hb.workspace(),
                    )?;
                    if !sol.is_converged() {
                        continue;
                    }
                    let d = relative_error(sol.harmonics(), &td.harmonics, 1, H);
                    let stable = hbal::stability::floquet(&model, &sol)?.is_stable();
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, stable));
                    }
                }
            }
            let td_max = td.samples[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            max_by_w.push((w, td_max));
            match best {
                Some((d, s)) => println!(
                    "| {w:.2} | {label} | {td_max:.5} | {} | {d:.1e} |",
                    if s { "stable" } else { "unstable" }
                ),
                None => println!("| {w:.2} | {label} | {td_max:.5} | none | - |"),
            }
        }
        if label == "down" {
            coexisting = max_by_w.len();
        }
    }
    let _ = coexisting;

    // Speed sweep of the two-shaft model (load fixed at its 6000 rpm value).
    let shaft = TwoShaft::new(6000.0);
    let model = shaft.model()?;
    let per_rpm = shaft.mesh_omega() / 6000.0;
    let start = Instant::now();
    let branch = Continuation::default().run(
        &model,
        HarmonicBasis::new(1000.0 * per_rpm, H)?,
        60000.0 * per_rpm,
        |_| {},
    )?;
    let peak = branch
        .points
        .iter()
        .max_by(|a, b| a.max_abs[0].total_cmp(&b.max_abs[0]))
        .ok_or("empty branch")?;
    println!(
        "\nTwo-shaft speed sweep 1000 -> 60000 rpm: {} points in {:.1} ms, {}; largest response {:.3e} rad at {:.0} rpm (mesh frequency {:.0} Hz)",
        branch.points.len(),
        start.elapsed().as_secs_f64() * 1e3,
        branch.stop,
        peak.max_abs[0],
        peak.omega / per_rpm,
        peak.omega / std::f64::consts::TAU
    );
    branch_plot(
        &out.join("two_shaft_speed_sweep.svg"),
        &branch,
        0,
        "Two-shaft model: speed sweep",
        "shaft speed (rpm)",
        |w| w / per_rpm,
    )?;
    println!("\nSVG and CSV written to {}/", out.display());
    Ok(())
}
