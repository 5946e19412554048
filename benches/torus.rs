//! Issue 34: the free-free two-stage drivetrain (`hbal::catalog::TwoStageTrain`, engine half
//! orders and both meshes as three torus bases, caps 8/4/4 on a 32×16×16 grid): one point
//! from the linear start (target < 50 ms) and a 200-point run-up 1000 → 6000 rpm (target
//! < 10 s). `cargo run --release --example torus_drivetrain` prints the same with the
//! convergence and truncation estimates.

use criterion::{criterion_group, criterion_main, Criterion};
use hbal::catalog::TwoStageTrain;
use hbal::torus::{IndexSet, NewtonKrylov, TorusBalance, TorusSweep, Truncation};
use std::hint::black_box;
use std::time::Duration;

const CAPS: [usize; 3] = [8, 4, 4];
const SAMPLES: [usize; 3] = [32, 16, 16];

fn rad_per_s(rpm: f64) -> f64 {
    rpm * std::f64::consts::TAU / 60.0
}

fn torus(c: &mut Criterion) {
    let model = TwoStageTrain::default().model().unwrap();
    let set = IndexSet::new(&TwoStageTrain::bases().unwrap(), &CAPS, Truncation::Box).unwrap();
    let point = || {
        let tm = TwoStageTrain::bind(&model).unwrap();
        let hb = TorusBalance::new(tm, set.clone(), &SAMPLES, rad_per_s(3000.0)).unwrap();
        NewtonKrylov::default().solve(&hb, None).unwrap()
    };
    assert!(point().converged);
    let speeds: Vec<f64> = (0..200)
        .map(|i| rad_per_s(1000.0 + 5000.0 * i as f64 / 199.0))
        .collect();
    let run_up = || {
        let tm = TwoStageTrain::bind(&model).unwrap();
        let mut hb = TorusBalance::new(tm, set.clone(), &SAMPLES, speeds[0]).unwrap();
        TorusSweep::default()
            .run(&mut hb, &speeds, |_, _| {})
            .unwrap()
    };
    let mut g = c.benchmark_group("torus_two_stage_train");
    g.sample_size(20);
    g.bench_function("one_point_3000rpm", |b| b.iter(|| black_box(point())));
    g.sample_size(10).measurement_time(Duration::from_secs(40));
    g.bench_function("run_up_200_points", |b| b.iter(|| black_box(run_up())));
}

criterion_group!(benches, torus);
criterion_main!(benches);
