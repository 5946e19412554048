//! Issue 31, item 3: a 2000-point run-up of a 10-DOF linear shaft line
//! (`tests/data/linear/shaft_line_10.toml`, 0.1 → 6000 rpm, H = 8) with stability and the
//! error estimate at every point: target < 0.2 s (median). Before the linear time-invariant
//! shortcut the same 2000 points took 3.2 s (arclength continuation, Runge–Kutta shooting per
//! point, a 2H Newton solve per point for the estimate) and its default run-up stopped at the
//! point limit short of 6000 rpm.

use criterion::{criterion_group, criterion_main, Criterion};
use hbal::continuation::Continuation;
use hbal::scene::Scene;
use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

fn linear_line_run_up(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/linear/shaft_line_10.toml");
    let scene = Scene::load(&path).unwrap();
    let rpm = std::f64::consts::TAU / 60.0;
    let basis = scene.basis.with_omega(0.1 * rpm).unwrap();
    let cont = Continuation {
        max_step: 0.04,
        max_points: 2000,
        error_estimate: true,
        ..Continuation::default()
    };
    let run = || cont.run(&scene.model, basis, 6000.0 * rpm, |_| {}).unwrap();
    let branch = run();
    println!(
        "linear line run-up: {} points to {:.1} rpm ({}), all stable: {}",
        branch.points.len(),
        branch.points.last().unwrap().omega / rpm,
        branch.stop,
        branch.points.iter().all(|p| p.stable() == Some(true))
    );
    let mut g = c.benchmark_group("linear");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.bench_function(
        "shaft_line_10dof_2000_points_with_stability_and_estimate",
        |b| b.iter(|| black_box(run())),
    );
    let lean = Continuation {
        stability: None,
        error_estimate: false,
        ..cont
    };
    g.bench_function("shaft_line_10dof_2000_points_bare", |b| {
        b.iter(|| black_box(lean.run(&scene.model, basis, 6000.0 * rpm, |_| {}).unwrap()))
    });
}

criterion_group!(benches, linear_line_run_up);
criterion_main!(benches);
