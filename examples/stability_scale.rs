//! Stability at scale: the Floquet multipliers of the drivetrain benchmark
//! (`hbal::catalog::Drivetrain`, 2000 rpm, m = 4 meshes, H = 32) against the number of DOFs,
//! on the reduced basis (modes below 3 H Ω plus attachment modes) with the exponential flow
//! (the default for these piecewise-affine laws) and with the Dormand–Prince flow, and the
//! dense monodromy matrix (`2n × 2n`) where it is affordable. A Markdown table on stdout.
//!
//! `cargo run --release --example stability_scale [-- --max-dofs N] [--dense-up-to N]
//! [--repeat R]` (defaults 10000, 20, 3). Times are medians over `R` runs of this thread's CPU
//! time (`/proc/thread-self/schedstat` on Linux, else wall clock): the machine may be shared.
//! "one analysis" is without the reduction's estimate, "with estimate" adds the comparison on
//! the basis with twice the cut-off (what `hbal solve` runs). The last line estimates a
//! 500-point run-up sweep with stability at n = 1000 from one point (two shooting periods, no
//! estimate, modes reused: see `examples/stability_sweep.rs` for the measured sweep).

mod common;

use common::{cpu_ms, flag, median};
use hbal::catalog::Drivetrain;
use hbal::stability::{Floquet, FloquetMethod, FloquetOptions, Integrator};
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Newton, Solution};
use hbal::{Model, Result};
use std::time::Instant;

/// Engine speed (rpm).
const RPM: f64 = 2000.0;

/// The median time of `repeat` analyses and the last result.
fn timed(
    repeat: usize,
    options: FloquetOptions,
    model: &Model,
    solution: &Solution,
) -> Result<(f64, Floquet)> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeat {
        let origin = Instant::now();
        let start = cpu_ms(origin);
        last = Some(options.compute(model, solution)?);
        times.push(cpu_ms(origin) - start);
    }
    Ok((median(times), last.expect("one run")))
}

/// `max_i min_j |a_i - b_j|` over the leading four of `a`.
fn distance(a: &Floquet, b: &Floquet) -> f64 {
    a.multipliers
        .iter()
        .take(4)
        .map(|m| {
            b.multipliers
                .iter()
                .map(|o| (m - o).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let max_dofs: usize = flag(&args, "--max-dofs", 10_000);
    let dense_up_to: usize = flag(&args, "--dense-up-to", 20);
    let repeat = flag(&args, "--repeat", 3_usize).max(1);
    println!("## Floquet multipliers of the drivetrain (m = 4, H = 32, {RPM} rpm)\n");
    println!("CPU ms, median of {repeat}; RK = Dormand–Prince 5(4), rtol 1e-8; exp = exponential flow.\n");
    println!("| n | HB point | basis r + a | one analysis RK | exp | ratio | with estimate RK | exp | ratio | dense RK | dense exp | max abs(μ) | exp vs RK | exp vs dense | estimate | steps RK / exp |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut sweep = None;
    for n in [20, 100, 1000, 10_000]
        .into_iter()
        .filter(|&n| n <= max_dofs)
    {
        let d = Drivetrain::default().with_dofs(n);
        let model = d.model()?;
        let basis = HarmonicBasis::new(d.fundamental(RPM), 32)?;
        let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed)?;
        let t = Instant::now();
        let solution: Solution = Newton::new().solve(&hb, &mut hb.workspace())?;
        let t_hb = t.elapsed().as_secs_f64() * 1e3;
        let reduced = FloquetOptions::new().with_method(FloquetMethod::Reduced);
        let with = |integrator, estimate| FloquetOptions {
            integrator,
            estimate,
            ..reduced
        };
        let (rk1, f_rk) = timed(
            repeat,
            with(Integrator::RungeKutta, false),
            &model,
            &solution,
        )?;
        let (exp1, f_exp) = timed(repeat, with(Integrator::Auto, false), &model, &solution)?;
        let (rk2, _) = timed(
            repeat,
            with(Integrator::RungeKutta, true),
            &model,
            &solution,
        )?;
        let (exp2, f_est) = timed(repeat, with(Integrator::Auto, true), &model, &solution)?;
        let info = f_est.reduction.clone().expect("a reduced analysis");
        let (dense_rk, dense_exp, to_dense) = if n <= dense_up_to {
            let dense = FloquetOptions::new().with_method(FloquetMethod::Dense);
            let (a, _) = timed(
                1,
                FloquetOptions {
                    integrator: Integrator::RungeKutta,
                    ..dense
                },
                &model,
                &solution,
            )?;
            let (b, f) = timed(repeat, dense, &model, &solution)?;
            (
                format!("{a:.0}"),
                format!("{b:.0}"),
                format!("{:.1e}", distance(&f_exp, &f)),
            )
        } else {
            ("-".into(), "-".into(), "-".into())
        };
        println!(
            "| {n} | {t_hb:.1} | {} + {} | {rk1:.0} | {exp1:.0} | {:.1} | {rk2:.0} | {exp2:.0} | {:.1} | {dense_rk} | {dense_exp} | {:.9} | {:.1e} | {to_dense} | {:.1e} (against {}) | {} / {} |",
            info.modes,
            info.attachment,
            rk1 / exp1,
            rk2 / exp2,
            f_exp.max_abs(),
            distance(&f_exp, &f_rk),
            info.estimate.unwrap_or(f64::NAN),
            info.comparison_dofs.unwrap_or(0),
            f_rk.steps,
            f_exp.steps,
        );
        if n == 1000 {
            sweep = Some((t_hb, exp1));
        }
    }
    if let Some((t_hb, t_floquet)) = sweep {
        println!(
            "\n500-point run-up sweep with stability at n = 1000 (estimated from one point: HB from the linear start, one analysis): {:.1} s (HB {:.1} s, stability {:.1} s)",
            500.0 * (t_hb + t_floquet) / 1e3,
            500.0 * t_hb / 1e3,
            500.0 * t_floquet / 1e3
        );
    }
    Ok(())
}
