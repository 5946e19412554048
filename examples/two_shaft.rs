//! The paper's two-shaft model (Bauer et al. 2021, section 4) at 60, 600, 6000 and 60000 rpm:
//! the time-domain reference against the iterative frequency-domain solver.
//!
//! Run: `cargo run --release --example two_shaft [-- --out DIR]` (SVGs go to `out/` by default).
//!
//! The model's fundamental is the mesh frequency 4Ω (harmonic k = shaft order 4k).

mod common;

use hbal::catalog::TwoShaft;
use hbal::compare::relative_error;
use hbal::report::{line_plot, median_time, Axis, Series};
use hbal::solve::coarse::coarse_harmonics;
use hbal::timesim::{TimeResponse, TimeSimulation};
use hbal::{Anderson, FixedPoint, HarmonicBalance, HarmonicBasis, Method, Solution, Termination};
use std::f64::consts::TAU;
use std::time::Duration;

/// Harmonics of the mesh frequency kept by the HB solver in table 1 (shaft orders up to 128).
const H: usize = 32;
/// Harmonics compared against the time-domain result.
const H_COMPARE: usize = 32;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = common::out_dir()?;
    let budget = Duration::from_millis(200);

    println!("Two-shaft model, H = {H} mesh harmonics (N = {}), fixed point with gamma = 0 (the paper's run).", HarmonicBasis::new(1.0, H)?.samples());
    println!("Time domain: DOP853 rtol 1e-10 from rest until successive periods agree to 1e-8 (relative).");
    println!("err = relative RMS distance to the time-domain periodic solution over mesh harmonics 0..={H_COMPARE}.\n");
    println!(
        "| rpm | TD wall | TD periods | TD steps | HB it 1 | HB it 2 | HB it 3 | HB it 4 | err it 1 | err it 2 | err it 3 | err it 4 |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut converged_rows = Vec::new();
    for rpm in [60.0, 600.0, 6000.0, 60000.0] {
        let case = TwoShaft::new(rpm);
        let model = case.model()?;
        let td_sim = TimeSimulation {
            samples: 4096,
            ..TimeSimulation::default()
        };
        let td = td_sim.run(&model, case.mesh_omega())?;
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(case.mesh_omega(), H)?)?;
        let mut ws = hb.workspace();
        let mut walls = Vec::new();
        let mut errs = Vec::new();
        let mut iterates = Vec::new();
        for it in 1..=4 {
            let solver = FixedPoint::new()
                .with_tolerance(0.0)?
                .with_max_iterations(it);
            let (wall, sol) = median_time(budget, || solver.solve(&hb, &mut ws));
            let sol = sol?;
            walls.push(wall);
            errs.push(relative_error(sol.harmonics(), &td.harmonics, 1, H_COMPARE));
            iterates.push(sol);
        }
        println!(
            "| {rpm} | {} | {} | {} | {} | {} | {} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} |",
            fmt(td.wall_time),
            td.periods,
            td.steps,
            fmt(walls[0]),
            fmt(walls[1]),
            fmt(walls[2]),
            fmt(walls[3]),
            errs[0],
            errs[1],
            errs[2],
            errs[3]
        );
        // Converged run: the paper's γ = 0 if it converges, else relaxation γ = 0.5.
        let mut conv = None;
        for gamma in [0.0, 0.5] {
            let solver = FixedPoint::new()
                .with_gamma(gamma)?
                .with_max_iterations(2000);
            let (wall, sol) = median_time(budget, || solver.solve(&hb, &mut ws));
            let sol = sol?;
            let first = sol.termination.clone();
            if sol.is_converged() {
                conv = Some((gamma, wall, sol, first));
                break;
            }
            converged_rows.push(format!(
                "| {rpm} | {gamma} | {} after {} iterations | | | |",
                sol.termination, sol.stats.iterations
            ));
        }
        if let Some((gamma, wall, sol, _)) = conv {
            converged_rows.push(format!(
                "| {rpm} | {gamma} | converged, {} iterations | {} | {:.2e} | {:.2e} |",
                sol.stats.iterations,
                fmt(wall),
                relative_error(sol.harmonics(), &td.harmonics, 1, H_COMPARE),
                sol.truncation_estimate()
            ));
            if rpm == 60.0 || rpm == 6000.0 {
                plots(&out, rpm, &td, &iterates, &sol)?;
            }
        }
    }
    println!("\nFixed point to a relative residual of 1e-10 (H = {H}):\n");
    println!("| rpm | gamma | result | HB wall | err vs TD | truncation estimate |");
    println!("|---:|---:|---|---:|---:|---:|");
    for r in &converged_rows {
        println!("{r}");
    }

    speed_up_table(budget)?;
    println!("\nSVG figures written to {}/", out.display());
    Ok(())
}

/// HB against the time domain at the same error: the time-domain run stops once successive
/// periods agree to 1e-6; HB takes the smallest H (N = 16H) whose error is at most the
/// time-domain run's (or 1e-6).
fn speed_up_table(budget: Duration) -> Result<(), Box<dyn std::error::Error>> {
    println!("\nSame error: TD (rtol 1e-8) until successive periods agree to 1e-6; HB (fastest of fixed point γ=0, Anderson on the paper's map and on the two-level map, fixed point γ=0.5; residual 1e-10)");
    println!("with the smallest H in 32..1024 (N = 16H) whose error is at most max(TD err, 1e-6).");
    println!("err against a converged time-domain reference (rtol 1e-12, periodicity 1e-10), mesh harmonics 0..={H_COMPARE}.\n");
    println!("| rpm | TD wall | TD periods | TD err | HB H | HB wall | HB iterations (method) | HB err | speed-up |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for rpm in [60.0, 600.0, 6000.0, 60000.0] {
        let case = TwoShaft::new(rpm);
        let model = case.model()?;
        let reference = TimeSimulation {
            rtol: 1e-12,
            steady_tolerance: 1e-10,
            samples: 4096,
            ..TimeSimulation::default()
        }
        .run(&model, case.mesh_omega())?;
        let td_sim = TimeSimulation {
            rtol: 1e-8,
            steady_tolerance: 1e-6,
            samples: 4096,
            ..TimeSimulation::default()
        };
        let (_, td) = median_time(budget, || td_sim.run(&model, case.mesh_omega()));
        let td = td?;
        let td_wall = td.wall_time;
        let td_err = relative_error(&td.harmonics, &reference.harmonics, 1, H_COMPARE);
        let target = td_err.max(1e-6);
        let mut row = None;
        let mut last = String::from("no converged run");
        'search: for h in [32usize, 64, 128, 256, 512, 1024] {
            let basis = HarmonicBasis::new(case.mesh_omega(), h)?
                .with_samples(16 * h)?
                .with_tail_correction(true);
            let hb = HarmonicBalance::new(&model, basis)?;
            let mut ws = hb.workspace();
            // The fastest converged of: the paper's iteration, Anderson on the paper's map and
            // on the two-level map, relaxed fixed point.
            let mut fastest: Option<(String, Duration, Solution, f64)> = None;
            let two_level = Anderson {
                coarse_harmonics: coarse_harmonics(&model, &basis),
                ..Anderson::new().with_max_iterations(2000)
            };
            for (label, method) in [
                (
                    "fixed point γ=0",
                    Method::FixedPoint(FixedPoint::new().with_max_iterations(2000)),
                ),
                (
                    "anderson",
                    Method::Anderson(Anderson::new().with_max_iterations(2000)),
                ),
                ("anderson, two-level", Method::Anderson(two_level)),
                (
                    "fixed point γ=0.5",
                    Method::FixedPoint(
                        FixedPoint::new().with_gamma(0.5)?.with_max_iterations(2000),
                    ),
                ),
            ] {
                let (wall, sol) = median_time(budget, || method.solve(&hb, None, &mut ws));
                let sol = sol?;
                if sol.termination != Termination::Converged {
                    last = format!("H {h}: {} ({label})", sol.termination);
                    continue;
                }
                let err = relative_error(sol.harmonics(), &reference.harmonics, 1, H_COMPARE);
                last = format!("H {h}: err {err:.2e}");
                if fastest.as_ref().is_none_or(|f| wall < f.1) {
                    fastest = Some((label.to_string(), wall, sol, err));
                }
            }
            if let Some((label, wall, sol, err)) = fastest {
                if err <= target {
                    row = Some((h, label, wall, sol, err));
                    break 'search;
                }
            }
        }
        match row {
            Some((h, label, wall, sol, err)) => println!(
                "| {rpm} | {} | {} | {td_err:.2e} | {h} | {} | {} ({label}) | {err:.2e} | {:.2}x |",
                fmt(td_wall),
                td.periods,
                fmt(wall),
                sol.stats.iterations,
                td_wall.as_secs_f64() / wall.as_secs_f64()
            ),
            None => println!(
                "| {rpm} | {} | {} | {td_err:.2e} | - | - | not reached ({last}) | - | - |",
                fmt(td_wall),
                td.periods
            ),
        }
    }
    Ok(())
}

/// The paper's figure 3 at one speed: q over one revolution and the amplitude spectrum.
fn plots(
    out: &std::path::Path,
    rpm: f64,
    td: &TimeResponse,
    iterates: &[Solution],
    converged: &Solution,
) -> Result<(), Box<dyn std::error::Error>> {
    let teeth = TwoShaft::TEETH as usize;
    let ns = td.samples[0].len();
    // One revolution = 4 mesh periods; x in shaft degrees.
    let revolution = |f: &dyn Fn(f64) -> f64| -> Vec<(f64, f64)> {
        (0..=4 * 256)
            .map(|j| {
                let shaft_deg = 360.0 * j as f64 / 1024.0;
                let theta = (TAU * teeth as f64 * shaft_deg / 360.0) % TAU;
                (shaft_deg, f(theta) * 1e6)
            })
            .collect()
    };
    let mut series = vec![Series::line(
        "time domain",
        (0..=teeth * ns)
            .map(|j| {
                (
                    360.0 * j as f64 / (teeth * ns) as f64,
                    td.samples[0][j % ns] * 1e6,
                )
            })
            .collect(),
    )];
    for (i, it) in iterates.iter().take(3).enumerate() {
        let label = if i == 0 {
            "HB iteration 1 (linear)".to_string()
        } else {
            format!("HB iteration {}", i + 1)
        };
        series.push(Series::line(label, revolution(&|t| it.displacement(0, t))));
    }
    series.push(Series::line(
        "HB converged",
        revolution(&|t| converged.displacement(0, t)),
    ));
    line_plot(
        &out.join(format!("two_shaft_{rpm}rpm_time.svg")),
        &format!("Two-shaft model at {rpm} rpm: q over one revolution"),
        &Axis::linear("shaft angle (deg)"),
        &Axis::linear("q (µrad)"),
        &series,
    )?;
    let spectrum = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (1..=H).map(|k| ((teeth * k) as f64, f(k))).collect()
    };
    let mut series = vec![Series::line(
        "time domain",
        spectrum(&|k| td.harmonic(0, k).norm() * 1e6),
    )];
    for (i, it) in iterates.iter().take(3).enumerate() {
        series.push(Series::markers(
            format!("HB iteration {}", i + 1),
            spectrum(&|k| it.harmonic(0, k).norm() * 1e6),
        ));
    }
    series.push(Series::markers(
        "HB converged",
        spectrum(&|k| converged.harmonic(0, k).norm() * 1e6),
    ));
    line_plot(
        &out.join(format!("two_shaft_{rpm}rpm_spectrum.svg")),
        &format!("Two-shaft model at {rpm} rpm: amplitude spectrum (static part omitted)"),
        &Axis::linear("shaft order"),
        &Axis::log("amplitude (µrad)"),
        &series,
    )?;
    Ok(())
}

fn fmt(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s >= 1.0 {
        format!("{s:.2} s")
    } else if s >= 1e-3 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{:.1} µs", s * 1e6)
    }
}
