//! Speed against error: harmonic balance with H = 4 ... 4096 (Newton up to 64; above, Anderson
//! on the two-level map, Newton's Jacobian on the harmonics up to 1.5 times the highest
//! natural frequency, here allowed up to 4096 real unknowns, and the per-harmonic step above),
//! automatic harmonics at tolerance 1e-6 on the periodic solution and on its harmonics, and the
//! time-domain reference with rtol = 1e-4 ... 1e-12, and, on the linear scenes with
//! piecewise-constant coefficients, the exact piecewise solution (`PiecewiseExact`, not
//! harmonic balance), all against a converged time-domain reference (rtol 1e-12 run to a
//! periodicity of 1e-11, its harmonics from 16384 samples a period; the timed runs take 4096).
//! Tells how many harmonics a scene needs for a given error, next to the error estimate every
//! solution reports, and the wall time each method needs for 1e-4 and 1e-6.
//!
//! Run: `cargo run --release --example accuracy [-- --out DIR]`

mod common;

use hbal::catalog::{Duffing, GearBacklash, TwoShaft};
use hbal::compare::relative_error;
use hbal::report::{line_plot, median_time, Axis, Series};
use hbal::solve::coarse::coarse_harmonics_within;
use hbal::solve::{estimate_error, solve_auto, AutoHarmonics, Control, Method, PiecewiseExact};
use hbal::timesim::TimeSimulation;
use hbal::Anderson;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
use std::time::Duration;

/// A case: file stem, title, model, fundamental, initial state of the time integration, the
/// harmonics tried.
type Case = (
    &'static str,
    &'static str,
    Model,
    f64,
    Option<(Vec<f64>, Vec<f64>)>,
    &'static [usize],
);

/// The harmonics tried on smooth and mildly non-smooth cases.
const H_SHORT: &[usize] = &[4, 8, 16, 32, 64, 128, 256, 512];
/// The harmonics tried at low speed, where the stiffness jumps excite harmonics up to the
/// natural frequency.
const H_LONG: &[usize] = &[64, 128, 256, 512, 1024, 2048, 4096];

/// The fastest wall time (µs) among `points` (wall, error) with an error at most `target`.
fn time_to(points: &[(f64, f64)], target: f64) -> Option<f64> {
    points
        .iter()
        .filter(|(_, e)| *e <= target)
        .map(|(w, _)| *w)
        .min_by(f64::total_cmp)
}

/// Harmonics compared (orders above a solution's H count as zero there).
const H_COMPARE: usize = 32;
/// The most harmonics of a solution's own compared (the reference's samples resolve 8192).
const H_OWN: usize = 1024;

/// Samples a period of the converged reference: at 60 rpm the stiffness jumps ring near
/// harmonic 771, and the harmonics 0..32 of 4096 samples are 6.6e-7 off (2.4e-9 with 16384).
const REFERENCE_SAMPLES: usize = 16384;
/// Samples a period of the timed time-domain runs: enough for 1e-6 everywhere (at 60 rpm to
/// 6.6e-7), and 16384 would cost the time domain up to 1.5 ms more.
const TD_SAMPLES: usize = 4096;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = common::out_dir()?;
    let shaft = TwoShaft::new(6000.0);
    let slow = TwoShaft::new(600.0);
    let slowest = TwoShaft::new(60.0);
    let cases: Vec<Case> = vec![
        (
            "two_shaft_6000rpm",
            "two-shaft model, 6000 rpm",
            shaft.model()?,
            shaft.mesh_omega(),
            None,
            H_SHORT,
        ),
        (
            "contact_ratio_1.6_6000rpm",
            "two-shaft model, 6000 rpm, contact ratio 1.6 (jumps between samples)",
            shaft.model_with_contact_ratio(1.6)?,
            shaft.mesh_omega(),
            None,
            H_SHORT,
        ),
        (
            "two_shaft_600rpm",
            "two-shaft model, 600 rpm",
            slow.model()?,
            slow.mesh_omega(),
            None,
            H_LONG,
        ),
        (
            "two_shaft_60rpm",
            "two-shaft model, 60 rpm",
            slowest.model()?,
            slowest.mesh_omega(),
            None,
            H_LONG,
        ),
        (
            "backlash_W1.0",
            "gear pair with backlash, W 1.0 (contact loss)",
            GearBacklash::default().model()?,
            1.0,
            Some((vec![1.1], vec![0.0])),
            H_SHORT,
        ),
        (
            "duffing_W1.0",
            "Duffing oscillator, W 1.0",
            Duffing::default().model()?,
            1.0,
            None,
            H_SHORT,
        ),
    ];
    let mut summary = Vec::new();
    let budget = Duration::from_millis(150);
    for (file, title, model, omega, initial, hs) in &cases {
        let reference = TimeSimulation {
            rtol: 1e-12,
            steady_tolerance: 1e-11,
            samples: REFERENCE_SAMPLES,
            initial: initial.clone(),
            ..TimeSimulation::default()
        }
        .run(model, *omega)?;
        println!("\n{title}: error = relative RMS distance over harmonics 0..={H_COMPARE} to the converged time-domain reference (missing harmonics count); error of harmonics 0..H: over the solution's own (at most 0..={H_OWN})\n");
        println!("| solver | setting | wall | error | its estimate | error of harmonics 0..H | its estimate |");
        println!("|---|---|---:|---:|---:|---:|---:|");
        let mut hb_points = Vec::new();
        let mut needed: Vec<(f64, Option<usize>)> = vec![(1e-2, None), (1e-4, None), (1e-6, None)];
        for &h in hs.iter() {
            let hb = HarmonicBalance::new(
                model,
                HarmonicBasis::new(*omega, h)?.with_tail_correction(true),
            )?;
            let mut ws = hb.workspace();
            let method = if h <= 64 {
                Method::Newton(Newton::new().with_tolerance(1e-12)?)
            } else {
                let mut a = Anderson::new()
                    .with_tolerance(1e-12)?
                    .with_max_iterations(2000);
                a.coarse_harmonics = coarse_harmonics_within(model, hb.basis(), 4096);
                Method::Anderson(a)
            };
            let (wall, sol) = median_time(budget, || method.solve(&hb, None, &mut ws));
            let sol = sol?;
            let err = relative_error(sol.harmonics(), &reference.harmonics, 1, H_COMPARE);
            let own = relative_error(sol.harmonics(), &reference.harmonics, 1, h.min(H_OWN));
            let estimate = estimate_error(model, &sol)
                .map(|e| format!("{:.1e} | {own:.2e} | {:.1e}", e.relative, e.kept_harmonics))
                .unwrap_or_else(|e| e.to_string());
            let status = if sol.is_converged() {
                String::new()
            } else {
                format!(" ({})", sol.termination)
            };
            println!(
                "| HB ({}{}) | H = {h}, N = {}{status} | {:.1} µs | {err:.2e} | {estimate} |",
                method.name(),
                match method {
                    Method::Anderson(Anderson {
                        coarse_harmonics: Some(hc),
                        ..
                    }) => format!(", Newton block H_c = {hc}"),
                    _ => String::new(),
                },
                hb.basis().samples(),
                wall.as_secs_f64() * 1e6,
            );
            if sol.is_converged() {
                hb_points.push((wall.as_secs_f64() * 1e6, err));
                for (target, n) in needed.iter_mut() {
                    if n.is_none() && err <= *target {
                        *n = Some(h);
                    }
                }
            }
        }
        let start = HarmonicBasis::new(*omega, 8)?;
        let newton = Method::Newton(Newton::new());
        for control in [Control::Solution, Control::Harmonics] {
            let auto = AutoHarmonics {
                control,
                ..AutoHarmonics::default()
            };
            let (wall, a) = median_time(budget, || solve_auto(model, start, &newton, auto));
            let a = a?;
            let err = relative_error(a.solution.harmonics(), &reference.harmonics, 1, H_COMPARE);
            let h = a.solution.basis().harmonics();
            let own = relative_error(
                a.solution.harmonics(),
                &reference.harmonics,
                1,
                h.min(H_OWN),
            );
            println!(
                "| HB auto ({}) | tolerance 1e-6 from H = 8: H = {h}{} | {:.1} µs | {err:.2e} | {:.1e} | {own:.2e} | {:.1e} |",
                match control {
                    Control::Solution => "periodic solution",
                    Control::Harmonics => "harmonics 0..H",
                    Control::Quantities => "every DOF and element coordinate",
                },
                if a.capped { " (cap)" } else { "" },
                wall.as_secs_f64() * 1e6,
                a.estimate.relative,
                a.estimate.kept_harmonics
            );
        }
        // The exact piecewise solution where it applies (linear, piecewise-constant
        // coefficients): H = 32, every harmonic compared exact.
        let mut exact_points = Vec::new();
        if PiecewiseExact::check(model).is_ok() {
            let basis = HarmonicBasis::new(*omega, H_COMPARE)?;
            let (wall, e) =
                median_time(budget, || PiecewiseExact::new().solve_exact(model, &basis));
            let e = e?;
            let wall = wall.as_secs_f64() * 1e6;
            let err = relative_error(e.solution.harmonics(), &reference.harmonics, 1, H_COMPARE);
            println!(
                "| exact piecewise (not HB) | H = {H_COMPARE} | {wall:.1} µs | {err:.2e} | {:.1e} | {err:.2e} | {:.1e} |",
                e.estimate.relative, e.estimate.kept_harmonics
            );
            exact_points.push((wall, err));
        }
        let mut td_points = Vec::new();
        for rtol in [1e-4, 1e-6, 1e-8, 1e-10, 1e-12] {
            let sim = TimeSimulation {
                rtol,
                steady_tolerance: (10.0 * rtol).max(1e-10),
                samples: TD_SAMPLES,
                initial: initial.clone(),
                ..TimeSimulation::default()
            };
            let (wall, td) = median_time(budget, || sim.run(model, *omega));
            let td = td?;
            let wall = wall.as_secs_f64() * 1e6;
            let err = relative_error(&td.harmonics, &reference.harmonics, 1, H_COMPARE);
            println!(
                "| time domain | rtol = {rtol:.0e}, {} periods, {:?} | {wall:.1} µs | {err:.2e} | | | |",
                td.periods,
                td.stop,
            );
            td_points.push((wall, err));
        }
        for (target, n) in &needed {
            match n {
                Some(h) => println!("\nError <= {target:.0e} needs H >= {h} (of {hs:?})."),
                None => println!(
                    "\nError <= {target:.0e} is not reached with H <= {}.",
                    hs.last().unwrap_or(&0)
                ),
            }
        }
        for target in [1e-4, 1e-6] {
            summary.push((
                *title,
                target,
                time_to(&hb_points, target),
                time_to(&td_points, target),
                time_to(&exact_points, target),
            ));
        }
        line_plot(
            &out.join(format!("accuracy_{file}.svg")),
            &format!("Error against wall time: {title}"),
            &Axis::log("wall time (µs)"),
            &Axis::log("relative error"),
            &[
                Series::line("harmonic balance", hb_points),
                Series::line("time domain, rtol = 1e-4 ... 1e-12", td_points),
                Series::line("exact piecewise (not HB), H = 32", exact_points),
            ],
        )?;
    }
    println!("\nWall time to reach an error (fastest setting that reaches it, same run):\n");
    println!("| case | error | harmonic balance | time domain | HB speed-up | exact piecewise (not HB) | its speed-up |");
    println!("|---|---:|---:|---:|---:|---:|---:|");
    let show = |t: Option<f64>| t.map_or("not reached".to_string(), |t| format!("{t:.0} µs"));
    let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
        (Some(a), Some(b)) if b >= 0.1 * a => format!("{:.1}x", b / a),
        (Some(a), Some(b)) => format!("{:.4}x (1/{:.0})", b / a, a / b),
        _ => "-".into(),
    };
    for (title, target, hb, td, exact) in summary {
        println!(
            "| {title} | {target:.0e} | {} | {} | {} | {} | {} |",
            show(hb),
            show(td),
            ratio(hb, td),
            exact.map_or("-".to_string(), |t| format!("{t:.0} µs")),
            ratio(exact, td),
        );
    }
    println!("\nSVG plots written to {}/", out.display());
    Ok(())
}
