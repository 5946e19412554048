//! The exact solution of linear scenes with piecewise-constant coefficients
//! (`method = "piecewise_exact"`) against independent references: the shared exact piecewise
//! solution at 6000 rpm, the time domain at tight tolerance at 60 and 600 rpm and with contact
//! ratio 1.6, and harmonic balance where it converges.

use crate::common::reference;
use hbal::catalog::TwoShaft;
use hbal::compare::relative_error;
use hbal::solve::PiecewiseExact;
use hbal::timesim::TimeSimulation;
use hbal::HarmonicBasis;

/// The time-domain reference at rtol 1e-12, run until periodic to 1e-11, its harmonics from
/// 16384 samples a period: at 60 rpm the jumps ring at harmonic 771, and 4096 samples put an
/// error of 6.6e-7 into the harmonics 0..32 (2.4e-9 with 16384).
fn time_domain(model: &hbal::Model, omega: f64) -> Vec<num_complex::Complex64> {
    TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        samples: 16384,
        ..TimeSimulation::default()
    }
    .run(model, omega)
    .unwrap()
    .harmonics
}

#[test]
fn the_two_shaft_model_at_6000_rpm_against_the_shared_reference() {
    let r = reference("seed_rect_6000rpm.json");
    let shaft = TwoShaft::new(6000.0);
    let basis = HarmonicBasis::new(shaft.mesh_omega(), 32).unwrap();
    let exact = PiecewiseExact::new()
        .solve_exact(&shaft.model().unwrap(), &basis)
        .unwrap();
    let err = relative_error(exact.solution.harmonics(), &r.harmonics, 1, 32);
    eprintln!("6000 rpm: {err:.2e}, estimate {:?}", exact.estimate);
    // The reference is good to about 1e-11.
    assert!(err < 1e-10, "{err:.2e}");
    // The rounding estimate (the periodicity solve's pivots) bounds the true error.
    let kept = exact.estimate.kept_harmonics;
    assert!(kept >= err && kept < 1e-9, "{kept:.2e} against {err:.2e}");
    // What H = 32 lacks: the rectangular stiffness's spectrum decays like l^-3.
    assert!(
        exact.estimate.relative > 1e-5 && exact.estimate.relative < 1e-2,
        "{:?}",
        exact.estimate
    );
}

#[test]
fn low_speeds_and_jumps_between_samples_against_the_time_domain() {
    for (rpm, ratio) in [(60.0, 1.5), (600.0, 1.5), (6000.0, 1.6)] {
        let shaft = TwoShaft::new(rpm);
        let model = shaft.model_with_contact_ratio(ratio).unwrap();
        let td = time_domain(&model, shaft.mesh_omega());
        let basis = HarmonicBasis::new(shaft.mesh_omega(), 32).unwrap();
        let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
        let err = relative_error(exact.solution.harmonics(), &td, 1, 32);
        eprintln!("{rpm} rpm, contact ratio {ratio}: {err:.2e}");
        assert!(err < 1e-8, "{rpm} rpm, contact ratio {ratio}: {err:.2e}");
        // What H = 32 lacks is reported, not hidden: at 60 rpm the ringing near harmonic 771
        // (the harmonics 33..64 alone hold 2.5 % of the RMS).
        let lacks = exact.estimate.relative;
        assert!(
            lacks > if rpm < 100.0 { 1e-2 } else { 1e-4 },
            "{rpm}: {lacks:.2e}"
        );
    }
}
