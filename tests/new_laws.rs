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
    Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/scenes")
            .join(name),
    )
    .unwrap()
}

/// The state `(q, q̇)` at θ = 0 of harmonics `x` (harmonic-major, `n` DOFs, fundamental ω).
fn state_at_zero(x: &[Complex64], n: usize, omega: f64) -> (Vec<f64>, Vec<f64>) {
    let h = x.len() / n - 1;
    let q = (0..n)
        .map(|i| (0..=h).map(|k| x[k * n + i].re).sum())
        .collect();
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

/// `gap_contact` with a time-varying stiffness `k(θ) = 5 + cos 2θ`, contact damping (the
/// force jumps at the contact edge) and an element offset, in Rust: against the time domain.
#[test]
fn gap_contact_with_offset_and_damping_matches_the_time_domain() {
    use hbal::force::{GapContact, MeshProfile, Offset};
    let contact = GapContact::with_profile(
        0.5,
        MeshProfile::Cosine {
            mean: 5.0,
            amplitude: 1.0,
        },
    )
    .with_teeth(2)
    .with_contact_damping(0.2);
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.1))
        .stiffness(hbal::nalgebra::DMatrix::from_element(1, 1, 1.0))
        .element("stop", &[("x", 1.0)], Offset::new(0.3, contact))
        .load("x", 0, 0.2, 0.0)
        .load("x", 1, 1.0, 0.0)
        .build()
        .unwrap();
    let omega = 1.1;
    let errors: Vec<f64> = [32, 64]
        .iter()
        .map(|&h| error_against_time_domain(&model, omega, h))
        .collect();
    eprintln!("gap_contact: {errors:?}");
    // In contact part of the period (the edge is at x = 0.8).
    let x = hb(&model, omega, 64);
    let peak = (0..64)
        .map(|j| {
            let t = std::f64::consts::TAU * j as f64 / 64.0;
            (0..=64)
                .map(|k| (x[k] * Complex64::from_polar(1.0, k as f64 * t)).re)
                .sum::<f64>()
        })
        .fold(f64::MIN, f64::max);
    assert!(peak > 0.9, "{peak}");
    assert!(errors[1] < 1e-4 && errors[1] < errors[0], "{errors:?}");
}
