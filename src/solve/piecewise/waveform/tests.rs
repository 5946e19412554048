//! The closed form in time against closed-form extremes, fine harmonics and the time domain.

use super::*;
use crate::catalog::TwoShaft;
use crate::force::{LinearSpring, MeshDamping, MeshProfile, MeshStiffness};
use crate::solve::PiecewiseExact;
use crate::{HarmonicBasis, Model};

#[test]
fn the_quintic_finds_the_peak_of_a_cosine() {
    // g = cos t around its maximum at 0.3: exact to O(δ⁶).
    let g = |t: f64| [(t - 0.3).cos(), -(t - 0.3).sin(), -(t - 0.3).cos()];
    let dt = TAU / 32.0;
    let v = interior_extremum(&g(0.2), &g(0.2 + dt), dt).unwrap();
    assert!((v - 1.0).abs() < 1e-8, "{v}");
    assert!(interior_extremum(&g(0.4), &g(0.4 + dt), dt).is_none());
}

#[test]
fn the_extremes_of_the_closed_form() {
    // An LTI scene: q = Q0 + |Q1| cos(...), its extremes Q0 ± |Q1| exactly; the spring's
    // mean force is k Q0.
    let model = Model::builder(&["x"])
        .mass_diagonal(&[2.0])
        .damping_triplets(&[(0, 0, 0.3)])
        .element("spring", &[("x", 1.0)], LinearSpring::new(50.0, 0.1))
        .load("x", 0, 1.0, 0.0)
        .load("x", 1, 0.5, 0.25)
        .build()
        .unwrap();
    let exact = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(1.7, 4).unwrap())
        .unwrap();
    let q = exact.solution.harmonics();
    let x = exact.extremes();
    let (lo, hi) = (q[0].re - q[1].norm(), q[0].re + q[1].norm());
    assert!(
        (x.dofs[0].0 - lo).abs() < 1e-12 && (x.dofs[0].1 - hi).abs() < 1e-12,
        "{x:?}"
    );
    assert_eq!(x.elements[0].coordinate, x.dofs[0]);
    assert!((x.elements[0].force_mean - 1.0).abs() < 1e-12, "{x:?}");
    // The two-shaft model at 6000 rpm: against the extremes of its harmonics at H = 4096
    // within 1e-8 of the range (3e-10 measured), and the mesh's mean force is the
    // mean load.
    let shaft = TwoShaft::new(6000.0);
    let model = shaft.model().unwrap();
    let basis = |h| HarmonicBasis::new(shaft.mesh_omega(), h).unwrap();
    let x = PiecewiseExact::new()
        .solve_exact(&model, &basis(32))
        .unwrap()
        .extremes();
    let fine = PiecewiseExact::new()
        .solve_exact(&model, &basis(4096))
        .unwrap();
    let (lo, hi) = fine.solution.extremes(0);
    let scale = hi - lo;
    eprintln!(
        "6000 rpm: [{:e}, {:e}] against [{lo:e}, {hi:e}], mean force {}",
        x.dofs[0].0, x.dofs[0].1, x.elements[0].force_mean
    );
    assert!((x.dofs[0].0 - lo).abs() < 1e-8 * scale);
    assert!((x.dofs[0].1 - hi).abs() < 1e-8 * scale);
    assert!((x.elements[0].force_mean - TwoShaft::L0).abs() < 1e-10 * TwoShaft::L0);
}

#[test]
fn the_time_series_is_the_time_domains() {
    // The two-shaft model at 600 rpm, where the ringing of every jump lies above H = 32:
    // sample by sample the time domain's final period at rtol 1e-13 (2.4e-9 apart; 9.8e-9
    // at rtol 1e-12: the difference is the time domain's error).
    let shaft = TwoShaft::new(600.0);
    let model = shaft.model().unwrap();
    let basis = HarmonicBasis::new(shaft.mesh_omega(), 32).unwrap();
    let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
    let points = 2048;
    let series = exact.time_series(points);
    let td = crate::timesim::TimeSimulation {
        rtol: 1e-13,
        steady_tolerance: 1e-12,
        samples: points,
        ..crate::timesim::TimeSimulation::default()
    }
    .run(&model, shaft.mesh_omega())
    .unwrap();
    let scale = td.samples[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = series[0]
        .iter()
        .zip(&td.samples[0])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f64, f64::max);
    eprintln!(
        "600 rpm: time series {:.1e} off the time domain",
        worst / scale
    );
    assert!(worst < 1e-8 * scale, "{:.2e}", worst / scale);
    // The harmonics 0..32 alone are far off between the samples of the ringing.
    let truncated = exact.solution.time_series(0, points);
    let off = truncated
        .iter()
        .zip(&td.samples[0])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f64, f64::max);
    assert!(off > 0.1 * scale, "{:.2e}", off / scale);
    assert!(exact.resolving_points() >= 256);
}

#[test]
fn every_sample_is_written_when_a_jump_falls_on_the_grid() {
    // The first jump on a sample (phase 2π - 2π k/points, as a user writes a phase near 2π):
    // the pieces' sample ranges still cover every sample once (a rounding had left one at
    // 0.0, found in review with phase 2π - 2π/500).
    for points in [64, 256, 500, 1000] {
        let phases = (1..40)
            .flat_map(|k| [k as f64, points as f64 - k as f64])
            .map(|k| TAU - TAU * k / points as f64)
            // The review's case (with 1000 samples).
            .chain([6.270618936565227]);
        for phase in phases {
            let mesh = MeshStiffness::new(
                1,
                MeshProfile::Rectangular {
                    one_tooth: 2.5e5,
                    two_tooth: 5e5,
                    contact_ratio: 1.5,
                },
                MeshDamping::Proportional(5e-6),
            )
            .with_phase(phase);
            let model = Model::builder(&["gear"])
                .mass_diagonal(&[1e-3])
                .element("mesh", &[("gear", 1.0)], mesh)
                .load("gear", 0, 10.0, 0.0)
                .load("gear", 1, 3.0, 0.0)
                .build()
                .unwrap();
            let exact = PiecewiseExact::new()
                .solve_exact(&model, &HarmonicBasis::new(2513.0, 8).unwrap())
                .unwrap();
            let series = exact.time_series(points);
            let (lo, hi) = exact.extremes().dofs[0];
            for (j, q) in series[0].iter().enumerate() {
                assert!(
                    *q >= lo - 1e-12 * hi && *q <= hi + 1e-12 * hi && *q > 0.0,
                    "points {points}, phase {phase}, sample {j}: {q:e} outside [{lo:e}, {hi:e}]"
                );
            }
        }
    }
}

#[test]
fn a_load_faster_than_the_natural_frequencies_sets_the_resolution() {
    // m = k = 1, d = 0.1, a load at order 40 of Ω = 1: q = Q0 + |Q40| cos(...), its extremes
    // need intervals per load period, not per natural period.
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .damping_triplets(&[(0, 0, 0.1)])
        .element("spring", &[("x", 1.0)], LinearSpring::new(1.0, 0.0))
        .load("x", 0, 0.5, 0.0)
        .load("x", 40, 1.0, 0.0)
        .build()
        .unwrap();
    let exact = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(1.0, 40).unwrap())
        .unwrap();
    let q = exact.solution.harmonics();
    let x = exact.extremes();
    let (lo, hi) = (q[0].re - q[40].norm(), q[0].re + q[40].norm());
    assert!(
        (x.dofs[0].1 - hi).abs() < 1e-9 * hi,
        "{:e} against {hi:e}",
        x.dofs[0].1
    );
    assert!(
        (x.dofs[0].0 - lo).abs() < 1e-9 * hi,
        "{:e} against {lo:e}",
        x.dofs[0].0
    );
    assert!(x.resolved && exact.resolving_points() >= 16 * 40);
}
