//! The laws `gap_contact`, `stop_spring`, `friction`, `quadratic_damper`, `polynomial_spring`
//! and the element offset, each on its example scene against the time-domain reference
//! (DOP853 at rtol 1e-12, started on the HB orbit's state at t = 0 and run until successive
//! periods agree to 1e-11). The error is [`relative_error`] over harmonics 0..=2H (the HB
//! solution has none above H, so its truncation counts).

use hbal::compare::relative_error;
use hbal::num_complex::Complex64;
use hbal::scene::Scene;
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
use std::path::Path;

fn scene(name: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes").join(name))
        .unwrap()
}

/// The state `(q, q̇)` at θ = 0 of harmonics `x` (harmonic-major, `n` DOFs, fundamental ω).
fn state_at_zero(x: &[Complex64], n: usize, omega: f64) -> (Vec<f64>, Vec<f64>) {
    let h = x.len() / n - 1;
    let q = (0..n).map(|i| (0..=h).map(|k| x[k * n + i].re).sum()).collect();
    let v = (0..n)
        .map(|i| {
            (1..=h)
                .map(|k| (x[k * n + i] * Complex64::new(0.0, k as f64 * omega)).re)
                .sum()
        })
        .collect();
    (q, v)
}

/// HB (Newton to 1e-12) with `h` harmonics at `omega`.
fn hb(model: &Model, omega: f64, h: usize) -> Vec<Complex64> {
    let hb = HarmonicBalance::new(model, HarmonicBasis::new(omega, h).unwrap()).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-12)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    sol.harmonics().to_vec()
}

/// The time-domain reference started on the state of `x`; its harmonics.
fn time_domain(model: &Model, omega: f64, x: &[Complex64]) -> Vec<Complex64> {
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        initial: Some(state_at_zero(x, model.n_dofs(), omega)),
        max_periods: 5000,
        ..TimeSimulation::default()
    }
    .run(model, omega)
    .unwrap();
    assert!(td.converged, "{:?} after {} periods", td.stop, td.periods);
    td.harmonics
}

/// HB with `h` harmonics against the time domain: the relative error over 0..=2H.
fn error_against_time_domain(model: &Model, omega: f64, h: usize) -> f64 {
    let x = hb(model, omega, h);
    let td = time_domain(model, omega, &x);
    relative_error(&x, &td, model.n_dofs(), 2 * h)
}

#[test]
fn polynomial_spring_matches_the_time_domain() {
    let s = scene("polynomial_spring.toml");
    let e = error_against_time_domain(&s.model, s.basis.omega(), 16);
    eprintln!("polynomial_spring: {e:.2e}");
    assert!(e < 1e-6, "{e:e}");
}

#[test]
fn friction_matches_the_time_domain() {
    let s = scene("friction_damper.toml");
    let e = error_against_time_domain(&s.model, s.basis.omega(), 48);
    eprintln!("friction: {e:.2e}");
    assert!(e < 1e-6, "{e:e}");
}

#[test]
fn quadratic_damper_matches_the_time_domain() {
    let s = scene("quadratic_damper.toml");
    let e = error_against_time_domain(&s.model, s.basis.omega(), 32);
    eprintln!("quadratic_damper: {e:.2e}");
    assert!(e < 1e-6, "{e:e}");
}

#[test]
fn stop_spring_matches_the_time_domain() {
    let s = scene("clutch_damper_stop_spring.toml");
    let e = error_against_time_domain(&s.model, s.basis.omega(), 24);
    eprintln!("stop_spring: {e:.2e}");
    assert!(e < 1e-4, "{e:e}");
}
