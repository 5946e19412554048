//! Performance targets of issue 2 (medians; compare ratios within one run):
//! - two-shaft at 6000 rpm, H = 32, 3 fixed-point iterations, plans built beforehand: <= 20 µs;
//! - HB cost flat across speed: 60000 rpm within 2x of 60 rpm;
//! - speed-up over the time-domain reference at the same error at 60000 rpm;
//! - issue 3: Newton on the backlash gear pair, H = 32, <= 50 µs per solve;
//! - issue 9: the exact piecewise solution (harmonics 0..32 exact) against the time domain to
//!   1e-6 across speed, the two-shaft model at 60 rpm included.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use hbal::catalog::TwoShaft;
use hbal::timesim::TimeSimulation;
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis};
use std::hint::black_box;
use std::time::Duration;

/// The default at a fixed H (the plain truncation) and with the tail correction (four more
/// FFTs of 512 samples per evaluation, 300 times more accurate at this H).
fn three_iterations(c: &mut Criterion) {
    let case = TwoShaft::new(6000.0);
    let model = case.model().unwrap();
    let solver = FixedPoint::new()
        .with_tolerance(0.0)
        .unwrap()
        .with_max_iterations(3);
    for (name, tail) in [
        ("two_shaft_6000rpm_H32_3_iterations", false),
        ("two_shaft_6000rpm_H32_3_iterations_tail", true),
    ] {
        let basis = HarmonicBasis::new(case.mesh_omega(), 32)
            .unwrap()
            .with_tail_correction(tail);
        let hb = HarmonicBalance::new(&model, basis).unwrap();
        assert_eq!(hb.tail_corrected(), tail);
        let mut ws = hb.workspace();
        c.bench_function(name, |b| {
            b.iter(|| black_box(solver.solve(&hb, &mut ws).unwrap()))
        });
    }
}

/// The paper's fixed point to convergence, at the default (the plain truncation) and with
/// the tail correction.
fn flat_across_speed(c: &mut Criterion) {
    for (name, tail) in [("hb_converged_H32", false), ("hb_converged_H32_tail", true)] {
        let mut group = c.benchmark_group(name);
        for rpm in [60.0, 600.0, 60000.0] {
            let case = TwoShaft::new(rpm);
            let model = case.model().unwrap();
            let basis = HarmonicBasis::new(case.mesh_omega(), 32)
                .unwrap()
                .with_tail_correction(tail);
            let hb = HarmonicBalance::new(&model, basis).unwrap();
            let mut ws = hb.workspace();
            let solver = FixedPoint::new();
            let sol = solver.solve(&hb, &mut ws).unwrap();
            assert!(sol.is_converged());
            eprintln!(
                "{name} {rpm} rpm: {} iterations, tail corrected {}",
                sol.stats.iterations,
                hb.tail_corrected()
            );
            group.bench_with_input(BenchmarkId::from_parameter(rpm), &rpm, |b, _| {
                b.iter(|| black_box(solver.solve(&hb, &mut ws).unwrap()))
            });
        }
        group.finish();
    }
}

fn time_domain(c: &mut Criterion) {
    let mut group = c.benchmark_group("time_domain_to_1e-6");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(3));
    for rpm in [60.0, 600.0, 6000.0, 60000.0] {
        let case = TwoShaft::new(rpm);
        let model = case.model().unwrap();
        let sim = TimeSimulation {
            rtol: 1e-8,
            steady_tolerance: 1e-6,
            samples: 256,
            ..TimeSimulation::default()
        };
        group.bench_with_input(BenchmarkId::from_parameter(rpm), &rpm, |b, _| {
            b.iter(|| black_box(sim.run(&model, case.mesh_omega()).unwrap()))
        });
    }
    group.finish();
}

/// The exact piecewise solution with H = 32 (its estimate's orders up to 4 times the natural
/// frequency included), at the speeds of `time_domain`.
fn piecewise_exact(c: &mut Criterion) {
    use hbal::solve::PiecewiseExact;
    let mut group = c.benchmark_group("piecewise_exact_H32");
    for rpm in [60.0, 600.0, 6000.0, 60000.0] {
        let case = TwoShaft::new(rpm);
        let model = case.model().unwrap();
        let basis = HarmonicBasis::new(case.mesh_omega(), 32).unwrap();
        let exact = PiecewiseExact::new();
        group.bench_with_input(BenchmarkId::from_parameter(rpm), &rpm, |b, _| {
            b.iter(|| black_box(exact.solve_exact(&model, &basis).unwrap()))
        });
    }
    group.finish();
}

/// Issue 3: Newton on the backlash gear pair (W = 0.7), 1 DOF, H = 32: <= 50 µs per solve; and
/// every method on it.
fn solvers_on_backlash(c: &mut Criterion) {
    use hbal::{Anderson, Broyden, Method, Newton};
    let model = hbal::catalog::GearBacklash::default().model().unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.7, 32).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let mut group = c.benchmark_group("backlash_W0.7_H32");
    for method in [
        Method::Newton(Newton::new()),
        Method::Broyden(Broyden::new()),
        Method::Anderson(Anderson::new()),
    ] {
        assert!(method.solve(&hb, None, &mut ws).unwrap().is_converged());
        group.bench_function(method.name(), |b| {
            b.iter(|| black_box(method.solve(&hb, None, &mut ws).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(
    benches,
    three_iterations,
    flat_across_speed,
    time_domain,
    piecewise_exact,
    solvers_on_backlash
);
criterion_main!(benches);
