//! Shared by the Floquet tests: the reference orbits of `tests/data/floquet/` (scipy, see its
//! README) and the solve warm-started from them, the small drivetrain, and the distance of two
//! sets of multipliers.

use hbal::catalog::Drivetrain;
use hbal::num_complex::Complex64;
use hbal::scene::Scene;
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Model, Newton, Solution};
use serde_json::Value;
use std::path::Path;

/// The scene `file` (relative to the crate root).
pub fn scene(file: &str) -> Scene {
    Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).unwrap()
}

/// The reference orbits of `tests/data/floquet/file`.
pub fn orbits(file: &str) -> Vec<Value> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/floquet")
        .join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    serde_json::from_str::<Value>(&text)
        .unwrap()
        .as_array()
        .unwrap()
        .clone()
}

/// A JSON array of numbers.
pub fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The reference orbit's leading Fourier coefficients as a warm start `Q_k = a_k - i b_k`.
pub fn warm_start(orbit: &Value, n: usize, h: usize) -> Vec<Complex64> {
    let mut q = vec![Complex64::default(); (h + 1) * n];
    for f in orbit["fourier"].as_array().unwrap() {
        let i = f["dof"].as_u64().unwrap() as usize;
        let (a, b) = (numbers(&f["cos"]), numbers(&f["sin"]));
        for k in 0..a.len().min(h + 1) {
            q[k * n + i] = Complex64::new(a[k], -b[k]);
        }
    }
    q
}

/// The reference orbit's multipliers.
pub fn reference_multipliers(orbit: &Value) -> Vec<Complex64> {
    orbit["multipliers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            let m = numbers(m);
            Complex64::new(m[0], m[1])
        })
        .collect()
}

/// Solves `model` at the reference's W with H = `h`, warm-started from its Fourier
/// coefficients (Newton, converged).
pub fn solve_at(label: &str, model: &Model, orbit: &Value, h: usize) -> Solution {
    let omega = orbit["W"].as_f64().unwrap();
    let hb = HarmonicBalance::new(model, HarmonicBasis::new(omega, h).unwrap()).unwrap();
    let sol = Newton::new()
        .solve_from(
            &hb,
            &warm_start(orbit, model.n_dofs(), h),
            &mut hb.workspace(),
        )
        .unwrap();
    assert!(sol.is_converged(), "{label}: {}", sol.termination);
    sol
}

/// Newton from rest on `basis` (converged).
pub fn solve(model: &Model, basis: HarmonicBasis, formulation: Formulation) -> Solution {
    let hb = HarmonicBalance::with_formulation(model, basis, formulation).unwrap();
    let s = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert!(s.is_converged(), "{}", s.termination);
    s
}

/// The small drivetrain with `dofs` DOFs: coarse teeth (mesh harmonics up to 8).
pub fn coarse_drivetrain(dofs: usize) -> Drivetrain {
    Drivetrain::default()
        .coarse_teeth(4)
        .unwrap()
        .with_dofs(dofs)
}

/// [`coarse_drivetrain`] solved at `rpm` with H = 8 (condensed formulation).
pub fn drivetrain(dofs: usize, rpm: f64) -> (Model, Solution) {
    let d = coarse_drivetrain(dofs);
    let model = d.model().unwrap();
    let basis = HarmonicBasis::new(d.fundamental(rpm), 8).unwrap();
    let s = solve(&model, basis, Formulation::Condensed);
    (model, s)
}

/// `max_i min_j |a_i - b_j|` both ways over all multipliers.
pub fn hausdorff(a: &[Complex64], b: &[Complex64]) -> f64 {
    one_way(a, b).max(one_way(b, a))
}

/// `max_i min_j |a_i - b_j|`.
pub fn one_way(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .map(|x| {
            b.iter()
                .map(|y| (x - y).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}
