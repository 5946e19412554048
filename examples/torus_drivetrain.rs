//! The free-free two-stage drivetrain of issue 34 on the torus: one point and a run-up, with
//! times (medians) and how far each result is converged.
//!
//! `cargo run --release --example torus_drivetrain`

use hbal::catalog::TwoStageTrain;
use hbal::torus::{IndexSet, NewtonKrylov, TorusBalance, Truncation};
use std::time::Instant;

fn rpm(x: f64) -> f64 {
    x * std::f64::consts::TAU / 60.0
}

fn main() -> hbal::Result<()> {
    let train = TwoStageTrain::default();
    let model = train.model()?;
    let caps = [8, 4, 4];
    let samples: Vec<usize> = std::env::var("SAMPLES")
        .map(|v| v.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or(vec![32, 16, 16]);
    let caps: Vec<usize> = std::env::var("CAPS")
        .map(|v| v.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or(caps.to_vec());
    let set = IndexSet::new(&TwoStageTrain::bases()?, &caps, Truncation::Box)?;
    println!(
        "two-stage train: {} DOFs, caps {caps:?}, {} lines, grid {samples:?}",
        model.n_dofs(),
        set.len()
    );
    let solver = NewtonKrylov::default();
    let mut times = Vec::new();
    let mut last = None;
    if let Ok(speed) = std::env::var("AT_RPM") {
        let hb = TorusBalance::new(
            TwoStageTrain::bind(&model)?,
            set.clone(),
            &samples,
            rpm(speed.parse().unwrap()),
        )?;
        let sol = solver.solve(&hb, None)?;
        println!("{}", sol.relative_residual);
        return Ok(());
    }
    let mut setup = Vec::new();
    for _ in 0..15 {
        let t = Instant::now();
        let hb = TorusBalance::new(
            TwoStageTrain::bind(&model)?,
            set.clone(),
            &samples,
            rpm(3000.0),
        )?;
        setup.push(t.elapsed().as_secs_f64());
        let sol = solver.solve(&hb, None)?;
        times.push(t.elapsed().as_secs_f64());
        last = Some(sol);
    }
    times.sort_by(f64::total_cmp);
    setup.sort_by(f64::total_cmp);
    let sol = last.unwrap();
    println!(
        "one point at 3000 rpm from the linear start: {:.1} ms (median of 15; {:.1} ms of it to set up), {} Newton steps, {} Jacobian products, residual {:.1e}, converged {}",
        1e3 * times[7],
        1e3 * setup[7],
        sol.iterations,
        sol.linear_iterations,
        sol.relative_residual,
        sol.converged
    );
    let points = 200;
    let t = Instant::now();
    let mut hb = TorusBalance::new(
        TwoStageTrain::bind(&model)?,
        set.clone(),
        &samples,
        rpm(1000.0),
    )?;
    let mut start: Option<Vec<_>> = None;
    let (mut failed, mut steps, mut products) = (0, 0, 0);
    let mut worst: f64 = 0.0;
    for i in 0..points {
        let speed = 1000.0 + 5000.0 * i as f64 / (points - 1) as f64;
        hb.set_omega(rpm(speed))?;
        let mut sol = solver.solve(&hb, start.as_deref())?;
        if !sol.converged && start.is_some() {
            sol = solver.solve(&hb, None)?;
        }
        failed += usize::from(!sol.converged);
        if !sol.converged || std::env::var("VERBOSE").is_ok() {
            eprintln!(
                "{speed:.0} rpm: {} steps, {} products, residual {:.1e}",
                sol.iterations, sol.linear_iterations, sol.relative_residual
            );
        }
        steps += sol.iterations;
        products += sol.linear_iterations;
        worst = worst.max(sol.relative_residual);
        start = Some(
            sol.unknowns
                .iter()
                .map(|&(a, b)| hbal::num_complex::Complex64::new(a, b))
                .collect(),
        );
    }
    println!(
        "run-up 1000 -> 6000 rpm, {points} points: {:.2} s, {failed} not converged, {steps} Newton steps, {products} Jacobian products, worst residual {worst:.1e}",
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
