//! The fused residual and its exact AFT Jacobian against central finite differences, and the
//! real packing against the complex form.

use hbal::force::{Backlash, CubicSpring, MeshDamping, MeshProfile, MeshStiffness};
use hbal::{HarmonicBalance, HarmonicBasis, Model};
use nalgebra::DMatrix;

fn two_dof_model() -> Model {
    Model::builder(&["p", "g"])
        .mass(DMatrix::from_row_slice(2, 2, &[1.0, 0.1, 0.1, 2.0]))
        .damping(DMatrix::from_row_slice(2, 2, &[0.05, 0.0, 0.0, 0.08]))
        .stiffness(DMatrix::from_row_slice(2, 2, &[3.0, -1.0, -1.0, 2.0]))
        .element(
            "mesh",
            &[("p", 0.5), ("g", -1.2)],
            MeshStiffness::new(
                3,
                MeshProfile::Fourier {
                    mean: 4.0,
                    cos: vec![1.0, 0.3],
                    sin: vec![0.5],
                },
                MeshDamping::Proportional(0.02),
            ),
        )
        .element("duffing", &[("g", 1.0)], CubicSpring::new(0.5, 0.8))
        .element(
            "contact",
            &[("p", 1.0)],
            Backlash::new(
                10.0,
                MeshProfile::Cosine {
                    mean: 2.0,
                    amplitude: 0.4,
                },
            ),
        )
        .load("p", 0, 0.3, 0.0)
        .load("p", 1, 0.2, 0.1)
        .load("g", 2, 0.0, 0.4)
        .build()
        .unwrap()
}

fn check(model: &Model, x: &[f64], h: usize, omega: f64, tol: f64) {
    let hb = HarmonicBalance::new(model, HarmonicBasis::new(omega, h).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let m = hb.layout().len();
    let mut r = vec![0.0; m];
    let mut jac = DMatrix::zeros(m, m);
    hb.residual_real_into(x, &mut r, Some(&mut jac), &mut ws)
        .unwrap();
    // The fused call gives the same residual as the residual alone.
    let mut r_only = vec![0.0; m];
    hb.residual_real_into(x, &mut r_only, None, &mut ws)
        .unwrap();
    assert_eq!(r, r_only);
    let mut worst: f64 = 0.0;
    let scale = jac.amax();
    for j in 0..m {
        let step = 1e-6;
        let mut xp = x.to_vec();
        let mut xm = x.to_vec();
        xp[j] += step;
        xm[j] -= step;
        let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
        hb.residual_real_into(&xp, &mut rp, None, &mut ws).unwrap();
        hb.residual_real_into(&xm, &mut rm, None, &mut ws).unwrap();
        for i in 0..m {
            let fd = (rp[i] - rm[i]) / (2.0 * step);
            worst = worst.max((fd - jac[(i, j)]).abs() / scale);
        }
    }
    assert!(worst < tol, "Jacobian mismatch {worst:e}");
}

#[test]
fn jacobian_matches_finite_differences_two_dof() {
    let model = two_dof_model();
    let h = 5;
    let m = 2 * (2 * h + 1);
    let x: Vec<f64> = (0..m)
        .map(|i| 0.3 * ((i as f64) * 1.7).sin() / (1.0 + (i / 4) as f64))
        .collect();
    check(&model, &x, h, 1.3, 1e-7);
}

#[test]
fn jacobian_matches_finite_differences_backlash_in_contact() {
    let model = hbal::catalog::GearBacklash::default().model().unwrap();
    let h = 8;
    let mut x = vec![0.0; 2 * h + 1];
    x[0] = 1.5; // engaged: u stays within (1.2, 1.8), away from the kink at 1
    x[1] = 0.2;
    x[2] = 0.1;
    x[3] = 0.05;
    check(&model, &x, h, 0.7, 1e-7);
}

#[test]
fn packing_round_trip_and_norm() {
    let layout = hbal::harmonic::RealLayout { n: 3, h: 4 };
    let x: Vec<f64> = (0..layout.len()).map(|i| (i as f64).cos()).collect();
    let mut q = vec![num_complex::Complex64::default(); 3 * 5];
    layout.unpack(&x, &mut q);
    let mut back = vec![0.0; layout.len()];
    layout.pack(&q, &mut back);
    assert_eq!(x, back);
    let complex_norm: f64 = q
        .iter()
        .enumerate()
        .map(|(i, v)| {
            if i < 3 {
                v.norm_sqr()
            } else {
                0.5 * v.norm_sqr()
            }
        })
        .sum::<f64>()
        .sqrt();
    assert!((layout.norm(&x) - complex_norm).abs() < 1e-14);
}

/// ∂R/∂Ω (analytic) against central differences in Ω, for the 2-DOF model and the backlash.
#[test]
fn omega_derivative_matches_finite_differences() {
    let backlash = hbal::catalog::GearBacklash::default().model().unwrap();
    let two = two_dof_model();
    for (model, h, omega) in [(&two, 5usize, 1.3), (&backlash, 8, 0.7)] {
        let mut hb = HarmonicBalance::new(model, HarmonicBasis::new(omega, h).unwrap()).unwrap();
        let m = hb.layout().len();
        let x: Vec<f64> = (0..m)
            .map(|i| 0.2 * ((i as f64) * 0.9).cos() + if i == 0 { 1.5 } else { 0.0 })
            .collect();
        crate::common::assert_omega_derivative(&mut hb, &x, "");
    }
}
