//! The free-free two-stage drivetrain of issue 34 on the torus (engine half orders, mesh 1 and
//! mesh 2 as three bases): one point from the linear start and a 200-point run-up
//! 1000 → 6000 rpm, with times (medians), convergence and the per-base truncation estimate.
//!
//! `cargo run --release --example torus_drivetrain [-- CAPS SAMPLES [TOTAL]]`, e.g.
//! `-- 8,8,8 32,32,32 12` for caps (8, 8, 8) on a 32³ grid in a diamond of total degree 12
//! (default: caps 8,4,4, grid 32,16,16, a box).

use hbal::catalog::TwoStageTrain;
use hbal::torus::{IndexSet, NewtonKrylov, TorusBalance, TorusSweep, Truncation};
use std::time::Instant;

fn rad_per_s(rpm: f64) -> f64 {
    rpm * std::f64::consts::TAU / 60.0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> hbal::Result<()> {
    let model = TwoStageTrain::default().model()?;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let list = |i: usize, default: [usize; 3]| -> Vec<usize> {
        args.get(i).map_or(default.to_vec(), |s| {
            s.split(',')
                .map(|x| x.parse().expect("a list like 8,4,4"))
                .collect()
        })
    };
    let (caps, samples) = (list(0, [8, 4, 4]), list(1, [32, 16, 16]));
    let truncation = args
        .get(2)
        .map_or(Truncation::Box, |t| Truncation::Diamond {
            total: t.parse().expect("a total degree"),
        });
    let set = IndexSet::new(&TwoStageTrain::bases()?, &caps, truncation)?;
    println!(
        "two-stage train: {} DOFs, bases {:?}, caps {caps:?} ({truncation:?}), {} lines, grid {samples:?}",
        model.n_dofs(),
        TwoStageTrain::bases()?.names(),
        set.len()
    );
    let solver = NewtonKrylov::default();
    let (mut total, mut setup, mut last) = (Vec::new(), Vec::new(), None);
    for _ in 0..15 {
        let t = Instant::now();
        let bound = TwoStageTrain::bind(&model)?;
        let hb = TorusBalance::new(bound, set.clone(), &samples, rad_per_s(3000.0))?;
        setup.push(t.elapsed().as_secs_f64());
        last = Some(solver.solve(&hb, None)?);
        total.push(t.elapsed().as_secs_f64());
    }
    let sol = last.expect("15 runs");
    println!(
        "one point at 3000 rpm from the linear start: {:.1} ms (median of 15; {:.1} ms to set up), {} Newton steps, {} Jacobian products, residual {:.1e}, converged {}",
        1e3 * median(total),
        1e3 * median(setup),
        sol.iterations,
        sol.linear_iterations,
        sol.relative_residual,
        sol.converged
    );
    for (name, e) in sol.bases.iter().zip(&sol.truncation) {
        match e {
            Some(e) => println!("  truncation of base `{name}`: {e:.1e} of the alternating TE"),
            None => println!("  truncation of base `{name}`: not estimated (grid too coarse)"),
        }
    }
    let points = 200;
    let speeds: Vec<f64> = (0..points)
        .map(|i| rad_per_s(1000.0 + 5000.0 * i as f64 / (points - 1) as f64))
        .collect();
    let t = Instant::now();
    let bound = TwoStageTrain::bind(&model)?;
    let mut hb = TorusBalance::new(bound, set, &samples, speeds[0])?;
    let sweep = TorusSweep {
        solver,
        ..Default::default()
    }
    .run(&mut hb, &speeds, |_, _| {})?;
    let elapsed = t.elapsed().as_secs_f64();
    let worst = sweep
        .points
        .iter()
        .map(|p| p.relative_residual)
        .fold(0.0, f64::max);
    let steps: usize = sweep.points.iter().map(|p| p.iterations).sum();
    let products: usize = sweep.points.iter().map(|p| p.linear_iterations).sum();
    println!(
        "run-up 1000 -> 6000 rpm, {points} points: {elapsed:.2} s, {} not converged (marked), {steps} Newton steps, {products} Jacobian products, worst residual {worst:.1e}",
        sweep.failures()
    );
    for p in sweep.points.iter().filter(|p| !p.converged) {
        println!(
            "  not converged at {:.0} rpm: residual {:.1e}",
            p.omega * 60.0 / std::f64::consts::TAU,
            p.relative_residual
        );
    }
    let hbal::torus::TorusStability::NotComputed { reason } = &sweep.stability;
    println!("stability: {reason}");
    Ok(())
}
