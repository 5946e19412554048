//! Issue 5 targets (medians):
//! - (issue 10) the 1000-DOF drivetrain's run-up with stability, about 500 points: <= 5 s
//!   (the HB orbit's stability; the exact orbit's alongside for the ratio);
//! - the gear-backlash curve, 1 DOF, H = 32, about 500 points with stability: < 0.2 s;
//! - Duffing (m 1, d 0.02, k 1, α 1, F 0.1), H = 7, Ω 0.5 → 3.0 through both folds,
//!   residual 1e-10: < 25 ms (NLvib under Octave: 2.5 s to a residual of 1e-5).

use criterion::{criterion_group, criterion_main, Criterion};
use hbal::catalog::{Duffing, GearBacklash};
use hbal::continuation::Continuation;
use hbal::stability::{FloquetOptions, Orbit};
use hbal::HarmonicBasis;
use std::hint::black_box;
use std::time::Duration;

fn gear_backlash_curve(c: &mut Criterion) {
    let model = GearBacklash::default().model().unwrap();
    let cont = Continuation {
        max_step: 0.03,
        ..Continuation::default()
    };
    let branch = cont
        .run(&model, HarmonicBasis::new(0.4, 32).unwrap(), 1.6, |_| {})
        .unwrap();
    println!(
        "gear backlash curve: {} points, {} folds",
        branch.points.len(),
        branch.folds()
    );
    let mut g = c.benchmark_group("sweeps");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.bench_function("gear_backlash_H32_with_stability", |b| {
        b.iter(|| {
            black_box(
                cont.run(&model, HarmonicBasis::new(0.4, 32).unwrap(), 1.6, |_| {})
                    .unwrap(),
            )
        })
    });
    let model = Duffing::default().model().unwrap();
    let cont = Continuation::default();
    let branch = cont
        .run(&model, HarmonicBasis::new(0.5, 7).unwrap(), 3.0, |_| {})
        .unwrap();
    println!(
        "duffing curve: {} points, {} folds",
        branch.points.len(),
        branch.folds()
    );
    g.bench_function("duffing_H7_through_both_folds", |b| {
        b.iter(|| {
            black_box(
                cont.run(&model, HarmonicBasis::new(0.5, 7).unwrap(), 3.0, |_| {})
                    .unwrap(),
            )
        })
    });
    let cont = Continuation {
        stability: None,
        ..Continuation::default()
    };
    g.bench_function("duffing_H7_through_both_folds_no_stability", |b| {
        b.iter(|| {
            black_box(
                cont.run(&model, HarmonicBasis::new(0.5, 7).unwrap(), 3.0, |_| {})
                    .unwrap(),
            )
        })
    });
    g.finish();
}

/// The 1000-DOF drivetrain scene's run-up from 1000 to 3000 rpm (about 500 points), with the
/// exact orbit's and the HB orbit's stability, and without.
fn drivetrain_runup(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenes/large/drivetrain_1000.toml");
    let scene = hbal::scene::Scene::load(&path).unwrap();
    let unit = scene.omega_per_speed;
    let basis = scene.basis.with_omega(1000.0 * unit).unwrap();
    let to = 3000.0 * unit;
    let mut g = c.benchmark_group("drivetrain_1000_runup");
    g.sample_size(10).measurement_time(Duration::from_secs(60));
    for (name, stability) in [
        ("no_stability", None),
        ("exact_orbit", Some(FloquetOptions::default())),
        (
            "hb_orbit",
            Some(FloquetOptions {
                orbit: Orbit::Harmonic,
                ..FloquetOptions::default()
            }),
        ),
    ] {
        let cont = Continuation {
            max_step: 0.009,
            method: scene.method,
            stability,
            ..Continuation::default()
        };
        let branch = cont.run(&scene.model, basis, to, |_| {}).unwrap();
        println!("drivetrain run-up {name}: {} points", branch.points.len());
        g.bench_function(name, |b| {
            b.iter(|| black_box(cont.run(&scene.model, basis, to, |_| {}).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, gear_backlash_curve, drivetrain_runup);
criterion_main!(benches);
