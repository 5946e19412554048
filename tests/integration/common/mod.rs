//! Shared helpers: the independently computed reference solutions in tests/data (copied from
//! ../shared/reference).

#![allow(dead_code)]

pub mod cli;
pub mod floquet;
pub mod galerkin;
pub mod hostile;
pub mod json_diff;
pub mod time_domain;

use num_complex::Complex64;

/// A reference periodic solution: harmonics 0..=32 and its fundamental.
pub struct Reference {
    pub omega: f64,
    pub harmonics: Vec<Complex64>,
    pub json: serde_json::Value,
}

pub fn reference(file: &str) -> Reference {
    let path = format!("{}/tests/data/{file}", env!("CARGO_MANIFEST_DIR"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let a = json["a"].as_array().unwrap();
    let b = json["b"].as_array().unwrap();
    let harmonics = a
        .iter()
        .zip(b)
        .map(|(a, b)| hbal::harmonic::from_cos_sin(a.as_f64().unwrap(), b.as_f64().unwrap()))
        .collect();
    Reference {
        omega: json["fundamental_angular_frequency"].as_f64().unwrap(),
        harmonics,
        json,
    }
}

/// Runs the `hbal` binary of this build with `args`.
pub fn hbal(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args(args)
        .output()
        .expect("run hbal")
}

/// `(max |J - FD|, max |J|)`: the residual's Jacobian at the real unknowns `x` of `hb`
/// against central differences with step `step`.
pub fn jacobian_against_differences(
    hb: &hbal::HarmonicBalance,
    x: &[f64],
    step: f64,
) -> (f64, f64) {
    let mut ws = hb.workspace();
    let m = x.len();
    let mut r = vec![0.0; m];
    let mut jac = nalgebra::DMatrix::zeros(m, m);
    hb.residual_real_into(x, &mut r, Some(&mut jac), &mut ws)
        .unwrap();
    let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
    let mut worst: f64 = 0.0;
    for col in 0..m {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[col] += step;
        xm[col] -= step;
        hb.residual_real_into(&xp, &mut rp, None, &mut ws).unwrap();
        hb.residual_real_into(&xm, &mut rm, None, &mut ws).unwrap();
        for i in 0..m {
            worst = worst.max(((rp[i] - rm[i]) / (2.0 * step) - jac[(i, col)]).abs());
        }
    }
    (worst, jac.amax())
}

/// `∂R/∂Ω` of `hb` at `x` against central differences of the residual in Ω (step 1e-6):
/// every entry within 1e-6 of the largest.
pub fn assert_omega_derivative(hb: &mut hbal::HarmonicBalance, x: &[f64], label: &str) {
    let omega = hb.basis().omega();
    let mut ws = hb.workspace();
    let m = x.len();
    let mut dr = vec![0.0; m];
    hb.omega_derivative_real_into(x, &mut dr, &mut ws).unwrap();
    let step = 1e-6;
    let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
    hb.set_omega(omega + step).unwrap();
    hb.residual_real_into(x, &mut rp, None, &mut ws).unwrap();
    hb.set_omega(omega - step).unwrap();
    hb.residual_real_into(x, &mut rm, None, &mut ws).unwrap();
    let scale = dr.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for i in 0..m {
        let fd = (rp[i] - rm[i]) / (2.0 * step);
        assert!(
            (fd - dr[i]).abs() < 1e-6 * scale,
            "{label} entry {i}: {fd} vs {}",
            dr[i]
        );
    }
}
