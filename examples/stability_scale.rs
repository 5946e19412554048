//! Stability at scale: the Floquet multipliers of the drivetrain benchmark
//! (`hbal::catalog::Drivetrain`, 2000 rpm, m = 4 meshes, H = 32) against the number of DOFs,
//! with the dense monodromy matrix (`2n × 2n`) where it is affordable and on the reduced basis
//! (modes below 3 H Ω plus attachment modes). A Markdown table on stdout.
//!
//! `cargo run --release --example stability_scale [-- --max-dofs N] [-- --dense-up-to N]`
//! (defaults 10000 and 100). "reduced" is one analysis on the basis without the accuracy
//! estimate; "with estimate" adds the second analysis on the basis with twice the cut-off.
//! The last line estimates a 500-point run-up sweep with stability at n = 1000 from the
//! measured costs (one warm-started Newton point and one reduced analysis per point).

use hbal::catalog::Drivetrain;
use hbal::stability::{FloquetMethod, FloquetOptions};
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Newton, Solution};
use std::time::Instant;

/// Engine speed (rpm).
const RPM: f64 = 2000.0;

fn argument(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() -> hbal::Result<()> {
    let max_dofs = argument("--max-dofs", 10_000);
    let dense_up_to = argument("--dense-up-to", 100);
    println!("## Floquet multipliers of the drivetrain (m = 4, H = 32, {RPM} rpm)\n");
    println!("| n | HB point ms | basis r + a | dense ms | reduced ms | with estimate ms | max abs(μ) dense | max abs(μ) reduced | estimate | distance to dense | neutral | steps |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
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
        let dense = (n <= dense_up_to).then(|| {
            let t = Instant::now();
            let f = FloquetOptions::new()
                .with_method(FloquetMethod::Dense)
                .compute(&model, &solution);
            (t.elapsed().as_secs_f64() * 1e3, f)
        });
        let reduced_options = FloquetOptions {
            estimate: false,
            ..FloquetOptions::new().with_method(FloquetMethod::Reduced)
        };
        let t = Instant::now();
        let reduced = reduced_options.compute(&model, &solution)?;
        let t_reduced = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let estimated = FloquetOptions::new()
            .with_method(FloquetMethod::Reduced)
            .compute(&model, &solution)?;
        let t_estimated = t.elapsed().as_secs_f64() * 1e3;
        let info = estimated.reduction.clone().expect("a reduced analysis");
        let (t_dense, mu_dense, distance) = match &dense {
            Some((t, Ok(f))) => (
                format!("{t:.1}"),
                format!("{:.6}", f.max_abs()),
                format!(
                    "{:.1e}",
                    reduced
                        .multipliers
                        .iter()
                        .take(4)
                        .map(|m| f
                            .multipliers
                            .iter()
                            .map(|o| (m - o).norm())
                            .fold(f64::INFINITY, f64::min))
                        .fold(0.0, f64::max)
                ),
            ),
            Some((_, Err(e))) => (format!("{e}"), "-".into(), "-".into()),
            None => ("-".into(), "-".into(), "-".into()),
        };
        println!(
            "| {n} | {t_hb:.1} | {} + {} | {t_dense} | {t_reduced:.1} | {t_estimated:.1} | {mu_dense} | {:.6} | {:.1e} (against {}) | {distance} | {} / {} | {} |",
            info.modes,
            info.attachment,
            reduced.max_abs(),
            info.estimate.unwrap_or(f64::NAN),
            info.comparison_dofs.unwrap_or(0),
            reduced.neutral,
            estimated.neutral,
            reduced.steps,
        );
        if n == 1000 {
            sweep = Some((t_hb, t_reduced));
        }
    }
    if let Some((t_hb, t_reduced)) = sweep {
        println!(
            "\n500-point run-up sweep with stability at n = 1000 (estimated from one point): {:.1} s (HB {:.1} s, stability {:.1} s)",
            500.0 * (t_hb + t_reduced) / 1e3,
            500.0 * t_hb / 1e3,
            500.0 * t_reduced / 1e3
        );
    }
    Ok(())
}
