//! HB and the time-domain reference against independently computed periodic solutions
//! (scipy DOP853 + Newton shooting, see ../shared/reference/README.md).

use crate::common;

use common::reference;
use hbal::catalog::{Duffing, GearBacklash, TwoShaft};
use hbal::compare::relative_error;
use hbal::timesim::TimeSimulation;
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis};

/// The paper's two-shaft model at 6000 rpm: HB converges to the reference as H grows and is
/// within 1e-6 with enough harmonics.
#[test]
fn two_shaft_hb_matches_reference() {
    let r = reference("seed_rect_6000rpm.json");
    let case = TwoShaft::new(6000.0);
    assert!((case.mesh_omega() - r.omega).abs() < 1e-9);
    let model = case.model().unwrap();
    let solver = FixedPoint::new()
        .with_gamma(0.5)
        .unwrap()
        .with_tolerance(1e-12)
        .unwrap()
        .with_max_iterations(2000);
    let mut errors = Vec::new();
    for h in [32usize, 128, 512] {
        let basis = HarmonicBasis::new(case.mesh_omega(), h)
            .unwrap()
            .with_samples(16 * h)
            .unwrap()
            .with_tail_correction(true);
        let hb = HarmonicBalance::new(&model, basis).unwrap();
        let sol = solver.solve(&hb, &mut hb.workspace()).unwrap();
        assert!(sol.is_converged(), "H {h}: {:?}", sol.termination);
        errors.push(relative_error(sol.harmonics(), &r.harmonics, 1, 32));
        // The default at a fixed H: the plain truncation.
        if h == 32 {
            let plain = HarmonicBalance::new(&model, basis.with_tail_correction(false)).unwrap();
            let sol = solver.solve(&plain, &mut plain.workspace()).unwrap();
            let e = relative_error(sol.harmonics(), &r.harmonics, 1, 32);
            assert!(
                (2e-4..4e-4).contains(&e),
                "plain truncation at H = 32: {e:.2e}"
            );
        }
    }
    eprintln!("errors {errors:?}");
    // Rectangular stiffness: the spectrum decays like k^-3; the truncated balance was good to
    // 2.7e-4, 1.2e-5, 7.4e-7, the tail correction (the coupling through the harmonics above
    // H) makes it 8.9e-7, 1.0e-8 and 1.6e-10 (the reference's own level is about 1e-11).
    assert!(
        errors[0] < 1e-6 && errors[1] < 2e-8 && errors[2] < 5e-10,
        "{errors:?}"
    );
}

/// The time-domain reference reproduces the shared reference and converges as rtol tightens.
#[test]
fn two_shaft_time_domain_converges_to_reference() {
    let r = reference("seed_rect_6000rpm.json");
    let case = TwoShaft::new(6000.0);
    let model = case.model().unwrap();
    let mut errors = Vec::new();
    for rtol in [1e-6, 1e-8, 1e-10, 1e-12] {
        let td = TimeSimulation {
            rtol,
            steady_tolerance: 1e-10,
            samples: 2048,
            ..TimeSimulation::default()
        }
        .run(&model, case.mesh_omega())
        .unwrap();
        assert!(td.converged);
        errors.push(relative_error(&td.harmonics, &r.harmonics, 1, 32));
    }
    assert!(errors[3] < 1e-9, "{errors:?}");
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 5.0, "no convergence with rtol: {errors:?}");
    }
}

/// Duffing at W = 1 and the gear pair with backlash at W = 0.5: the time-domain reference
/// against the shared solutions. (The paper's fixed point does not converge on either: both
/// have a harmonic on the linear resonance; the accelerated solvers of issue 3 take them.)
#[test]
fn duffing_time_domain_matches_reference() {
    let r = reference("duffing_W1.00_unique.json");
    let model = Duffing::default().model().unwrap();
    let td = TimeSimulation {
        rtol: 1e-11,
        steady_tolerance: 1e-11,
        samples: 256,
        ..TimeSimulation::default()
    }
    .run(&model, r.omega)
    .unwrap();
    assert!(td.converged);
    let err = relative_error(&td.harmonics, &r.harmonics, 1, 32);
    assert!(err < 1e-8, "TD error {err}");
}

#[test]
fn gear_backlash_time_domain_matches_reference() {
    let r = reference("kahraman_A_W0.50_unique.json");
    let model = GearBacklash::default().model().unwrap();
    let td = TimeSimulation {
        rtol: 1e-11,
        steady_tolerance: 1e-10,
        samples: 256,
        initial: Some((vec![1.1], vec![0.0])),
        ..TimeSimulation::default()
    }
    .run(&model, r.omega)
    .unwrap();
    assert!(td.converged);
    let err = relative_error(&td.harmonics, &r.harmonics, 1, 32);
    assert!(err < 1e-8, "TD error {err}");
}

/// Contact loss (W = 1: the gear pair opens its backlash, min x < b): the time-domain reference
/// converges as rtol tightens, although the contact kink is left to the error control.
#[test]
fn gear_backlash_time_domain_converges_with_contact_loss() {
    let model = GearBacklash::default().model().unwrap();
    let mut runs = Vec::new();
    for rtol in [1e-10, 1e-11, 1e-12] {
        let td = TimeSimulation {
            rtol,
            steady_tolerance: 1e-10,
            samples: 512,
            initial: Some((vec![1.1], vec![0.0])),
            ..TimeSimulation::default()
        }
        .run(&model, 1.0)
        .unwrap();
        assert!(td.converged, "rtol {rtol}: {:?}", td.stop);
        let min = td.samples[0].iter().cloned().fold(f64::MAX, f64::min);
        assert!(min < 0.95, "no contact loss: min x = {min}");
        runs.push(td.harmonics);
    }
    let d1 = relative_error(&runs[0], &runs[2], 1, 32);
    let d2 = relative_error(&runs[1], &runs[2], 1, 32);
    assert!(d1 < 1e-6 && d2 < d1 / 2.0, "{d1:e} {d2:e}");
}

/// Integration noise above the steady tolerance stops the run as stalled instead of running
/// for 100 000 periods.
#[test]
fn time_domain_reports_a_stall() {
    let model = GearBacklash::default().model().unwrap();
    let td = TimeSimulation {
        rtol: 1e-6,
        steady_tolerance: 1e-12,
        stall_periods: 50,
        samples: 64,
        initial: Some((vec![1.1], vec![0.0])),
        ..TimeSimulation::default()
    }
    .run(&model, 1.0)
    .unwrap();
    assert_eq!(td.stop, hbal::timesim::TimeStop::Stalled);
    assert!(td.periods < 2000, "{}", td.periods);
}

/// Floquet multipliers (shooting-polished monodromy) against the shared references: 1e-6
/// absolute in the moduli.
#[test]
fn floquet_multipliers_match_references() {
    use hbal::stability::floquet;
    use hbal::Newton;
    let cases: Vec<(&str, hbal::Model, usize)> = vec![
        (
            "seed_rect_6000rpm.json",
            TwoShaft::new(6000.0).model().unwrap(),
            128,
        ),
        (
            "kahraman_A_W0.50_unique.json",
            GearBacklash::default().model().unwrap(),
            32,
        ),
        (
            "duffing_W1.00_unique.json",
            Duffing::default().model().unwrap(),
            15,
        ),
    ];
    for (file, model, h) in cases {
        let r = reference(file);
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(r.omega, h).unwrap()).unwrap();
        let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
        assert!(sol.is_converged(), "{file}");
        let f = floquet(&model, &sol).unwrap();
        let expected: Vec<f64> = r.json["floquet_multipliers_abs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(f.multipliers.len(), expected.len(), "{file}");
        assert!(f.polished, "{file}: shooting did not converge");
        for (got, want) in f.multipliers.iter().zip(&expected) {
            eprintln!("{file}: |μ| {:.12e} vs {want:.12e}", got.norm());
            assert!(
                (got.norm() - want).abs() < 1e-6,
                "{file}: |μ| {} vs {want}",
                got.norm()
            );
        }
        assert!(f.is_stable(), "{file}");
    }
}
