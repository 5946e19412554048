//! NLvib's example 03 (Krack & Gross, *Harmonic Balance for Nonlinear Vibration Problems*,
//! Springer 2019; EXAMPLES/03_twoDOFoscillator_unilateralSpring): two unit masses, a force
//! `0.1 cos Ωt` on the second and a unilateral spring `100 (q1 - 1)⁺` on the first, written
//! with `gap_contact` in the original coordinates. As in NLvib (H = 21), the frequency
//! response is continued from Ω = 0.8 down to 0.5 through both turning points; stable points
//! are checked against the time-domain reference.

use crate::common;

use common::time_domain::state_at_zero;
use hbal::compare::relative_error;
use hbal::continuation::{BranchPoint, BranchStop, Continuation};
use hbal::num_complex::Complex64;
use hbal::scene::Scene;
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
use std::path::Path;

fn scene() -> Scene {
    Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/scenes/nlvib_03_unilateral_spring.toml"),
    )
    .unwrap()
}

/// The branch point's orbit re-solved with `h` harmonics (Newton from its harmonics).
fn refine(model: &Model, p: &BranchPoint, h: usize) -> Vec<Complex64> {
    let n = model.n_dofs();
    let hb = HarmonicBalance::new(model, HarmonicBasis::new(p.omega, h).unwrap()).unwrap();
    let start = hbal::harmonic::embed(&p.harmonics, n, 1, h);
    let sol = Newton::new()
        .with_tolerance(1e-12)
        .unwrap()
        .solve_from(&hb, &start, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "Ω {}: {}", p.omega, sol.termination);
    sol.harmonics().to_vec()
}

/// The time-domain reference started on the state of `x` at t = 0.
fn time_domain(model: &Model, omega: f64, x: &[Complex64]) -> Vec<Complex64> {
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-10,
        initial: Some(state_at_zero(x, model.n_dofs(), omega)),
        max_periods: 5000,
        ..TimeSimulation::default()
    }
    .run(model, omega)
    .unwrap();
    assert!(td.converged, "Ω {omega}: {:?}", td.stop);
    td.harmonics
}

#[test]
fn frequency_response_turns_twice_and_matches_the_time_domain() {
    let s = scene();
    assert_eq!(s.basis.harmonics(), 21);
    let branch = Continuation::default()
        .run(&s.model, s.basis, 0.5, |_| {})
        .unwrap();
    assert_eq!(branch.stop, BranchStop::Reached);
    assert_eq!(branch.folds(), 2);
    // The step grows where the tangent hardly turns, however many corrector iterations the
    // stiff contact costs: 192 points (341 with the corrector's iterations alone, 831 before
    // the steps were scaled by the point's size).
    assert!(branch.points.len() <= 200, "{} points", branch.points.len());
    let mut folds: Vec<f64> = branch.points.iter().filter_map(|p| p.fold_omega).collect();
    folds.sort_by(f64::total_cmp);
    eprintln!("folds at {folds:?}");
    assert_eq!(folds.len(), 2, "{folds:?}");
    // The lower branch jumps up at 0.6535 (just after the contact starts to touch: the branch
    // has a corner there, and the interpolated fold moves by 1e-4 with the step size), the
    // resonance peak turns at 0.7556 (H = 21).
    assert!((folds[0] - 0.6535).abs() < 5e-4, "{folds:?}");
    assert!((folds[1] - 0.75563).abs() < 1e-4, "{folds:?}");
    // The peak: the first mass well beyond the gap.
    let peak = branch
        .points
        .iter()
        .map(|p| p.max_abs[0])
        .fold(0.0, f64::max);
    eprintln!("peak max |q1| {peak}");
    assert!(peak > 1.8 && peak < 1.9, "{peak}");

    // Stable points on the upper branch (after both folds) and on the lower one (before the
    // first), each re-solved with H = 128 and compared with the time domain.
    let second_fold = branch
        .points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.fold)
        .map(|(i, _)| i)
        .nth(1)
        .unwrap();
    let near = |range: std::ops::Range<usize>, omega: f64| {
        range
            .min_by(|&a, &b| {
                let d = |i: usize| (branch.points[i].omega - omega).abs();
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    let n = s.model.n_dofs();
    let first_fold = branch.points.iter().position(|p| p.fold).unwrap();
    for (i, contact) in [
        (near(second_fold..branch.points.len(), 0.70), true),
        (near(second_fold..branch.points.len(), 0.64), true),
        (near(0..first_fold, 0.70), false),
    ] {
        let p = &branch.points[i];
        assert_eq!(p.stable(), Some(true), "Ω {}", p.omega);
        assert_eq!(p.max_abs[0] > 1.0, contact, "Ω {}", p.omega);
        let x = refine(&s.model, p, 128);
        let td = time_domain(&s.model, p.omega, &x);
        let e = relative_error(&x, &td, n, 256);
        let h21 = relative_error(&p.harmonics, &td, n, 256);
        eprintln!(
            "Ω {:.4}: H = 128 error {e:.2e}, H = 21 error {h21:.2e}",
            p.omega
        );
        assert!(e < 1e-4, "Ω {}: {e:e}", p.omega);
    }
}
