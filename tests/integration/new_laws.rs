//! The laws `gap_contact`, `stop_spring`, `friction`, `quadratic_damper`, `polynomial_spring`
//! and the element offset, each on its example scene against the time-domain reference
//! (DOP853 at rtol 1e-12, started on the HB orbit's state at t = 0 and run until successive
//! periods agree to 1e-11). The error is [`relative_error`] over harmonics 0..=2H (the HB
//! solution has none above H, so its truncation counts).

use crate::common;

use common::time_domain::{error_against_time_domain, hb};
use hbal::num_complex::Complex64;
use hbal::scene::Scene;
use hbal::Model;
use std::path::Path;

fn scene(name: &str) -> Scene {
    Scene::load(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/scenes")
            .join(name),
    )
    .unwrap()
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
