//! Fixed point vs accelerated solvers on the same harmonic residual: residual history per
//! iteration and against wall time, as a table and SVG plots.
//!
//! Run: `cargo run --release --example convergence [-- --out DIR]`

mod common;

use hbal::catalog::{Duffing, GearBacklash, TwoShaft};
use hbal::report::{line_plot, median_time, Axis, Series};
use hbal::{Anderson, Broyden, FixedPoint, HarmonicBalance, HarmonicBasis, Method, Model, Newton};
use std::time::Duration;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = common::out_dir()?;
    let two_shaft = TwoShaft::new(6000.0);
    let cases: Vec<(&str, &str, Model, f64, usize)> = vec![
        (
            "two_shaft_6000rpm",
            "two-shaft model, 6000 rpm, H 32",
            two_shaft.model()?,
            two_shaft.mesh_omega(),
            32,
        ),
        (
            "backlash_W0.7",
            "gear pair with backlash, W 0.7 (no impact), H 32",
            GearBacklash::default().model()?,
            0.7,
            32,
        ),
        (
            "backlash_W1.0",
            "gear pair with backlash, W 1.0 (contact loss), H 32",
            GearBacklash::default().model()?,
            1.0,
            32,
        ),
        (
            "duffing_W1.0",
            "Duffing at its linear resonance, W 1.0, H 7",
            Duffing::default().model()?,
            1.0,
            7,
        ),
        (
            "duffing_W1.2",
            "Duffing, W 1.2, H 7",
            Duffing::default().model()?,
            1.2,
            7,
        ),
    ];
    let methods = [
        Method::FixedPoint(FixedPoint::new()),
        Method::FixedPoint(FixedPoint::new().with_gamma(0.5)?.with_max_iterations(500)),
        Method::Anderson(Anderson::new()),
        Method::Broyden(Broyden::new()),
        Method::Newton(Newton::new()),
    ];
    println!("Relative residual tolerance 1e-10; wall time = median of repeated solves (plans built beforehand).\n");
    println!(
        "| case | method | result | iterations | residual evaluations | Jacobians | LU | wall |"
    );
    println!("|---|---|---|---:|---:|---:|---:|---:|");
    for (file, title, model, omega, h) in &cases {
        let hb = HarmonicBalance::new(model, HarmonicBasis::new(*omega, *h)?)?;
        let mut ws = hb.workspace();
        let mut by_iteration = Vec::new();
        let mut by_time = Vec::new();
        for method in &methods {
            let label = match method {
                Method::FixedPoint(f) => format!("fixed point γ={}", f.gamma),
                m => m.name().to_string(),
            };
            let (wall, sol) = median_time(Duration::from_millis(100), || {
                method.solve(&hb, None, &mut ws)
            });
            let sol = sol?;
            println!(
                "| {title} | {label} | {} | {} | {} | {} | {} | {:.1} µs |",
                sol.termination,
                sol.stats.iterations,
                sol.stats.residual_evaluations,
                sol.stats.jacobians,
                sol.stats.factorizations,
                wall.as_secs_f64() * 1e6
            );
            by_iteration.push(Series::line(
                label.clone(),
                sol.history
                    .iter()
                    .enumerate()
                    .map(|(i, r)| (i as f64, *r))
                    .collect(),
            ));
            by_time.push(Series::line(
                label,
                sol.history_seconds
                    .iter()
                    .zip(&sol.history)
                    .map(|(t, r)| (t * 1e6 + 1.0, *r))
                    .collect(),
            ));
        }
        line_plot(
            &out.join(format!("convergence_{file}_iterations.svg")),
            &format!("Residual per iteration: {title}"),
            &Axis::linear("iteration"),
            &Axis::log("relative residual"),
            &by_iteration,
        )?;
        line_plot(
            &out.join(format!("convergence_{file}_time.svg")),
            &format!("Residual against time: {title}"),
            &Axis::log("wall time (µs, +1)"),
            &Axis::log("relative residual"),
            &by_time,
        )?;
    }
    println!("\nSVG plots written to {}/", out.display());
    Ok(())
}
