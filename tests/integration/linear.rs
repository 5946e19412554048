//! Linear models against their closed-form frequency response.

use hbal::force::{LinearSpring, MeshDamping, MeshProfile, MeshStiffness};
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis, Model};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// 1 DOF: m x'' + c x' + k x = F0 + F1 cos(Ωt) + G3 sin(3Ωt); X_k = F_k / (k - (kΩ)² m + i kΩ c).
#[test]
fn one_dof_matches_closed_form() {
    let (m, c, k, w) = (2.0, 0.3, 50.0, 3.7);
    let model = Model::builder(&["x"])
        .mass_diagonal(&[m])
        .element("spring", &[("x", 1.0)], LinearSpring::new(k, c))
        .load("x", 0, 1.5, 0.0)
        .load("x", 1, 2.0, 0.0)
        .load("x", 3, 0.0, -0.7)
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(w, 5).unwrap()).unwrap();
    let sol = FixedPoint::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert!(sol.is_converged());
    // A linear time-invariant model is solved exactly by the first (linear) iteration.
    assert_eq!(sol.stats.iterations, 1);
    assert_eq!(sol.stats.ffts, 0, "LTI elements must not cost FFTs");
    let z = |order: f64| Complex64::new(k - (order * w).powi(2) * m, order * w * c);
    let expected = [
        (0, Complex64::new(1.5, 0.0) / z(0.0)),
        (1, Complex64::new(2.0, 0.0) / z(1.0)),
        (2, Complex64::default()),
        (3, Complex64::new(0.0, 0.7) / z(3.0)), // -0.7 sin = Re(+0.7i e^{i3θ})
    ];
    for (order, x) in expected {
        let got = sol.harmonic(0, order);
        assert!((got - x).norm() < 1e-14, "order {order}: {got} vs {x}");
    }
    // The time series agrees with the closed form too.
    let theta: f64 = 0.9;
    let exact = (Complex64::new(1.5, 0.0) / z(0.0)).re
        + (Complex64::new(2.0, 0.0) / z(1.0) * Complex64::from_polar(1.0, theta)).re
        + (Complex64::new(0.0, 0.7) / z(3.0) * Complex64::from_polar(1.0, 3.0 * theta)).re;
    assert!((sol.displacement(0, theta) - exact).abs() < 1e-14);
}

/// 2 DOF chain with a gear-like element coupling two DOFs with weights: against a direct
/// complex solve of (K - ω² M + iω D) X = F.
#[test]
fn two_dof_with_weighted_element_matches_direct_solve() {
    let (w, r1, r2) = (11.0, 0.05, 0.12);
    let m = DMatrix::from_row_slice(2, 2, &[0.02, 0.0, 0.0, 0.09]);
    let k = DMatrix::from_row_slice(2, 2, &[800.0, 0.0, 0.0, 300.0]);
    let d = DMatrix::from_row_slice(2, 2, &[0.1, 0.0, 0.0, 0.2]);
    let (km, cm) = (2e5, 15.0);
    let model = Model::builder(&["pinion", "gear"])
        .mass(m.clone())
        .stiffness(k.clone())
        .damping(d.clone())
        .element(
            "mesh",
            &[("pinion", r1), ("gear", r2)],
            MeshStiffness::new(
                3,
                MeshProfile::Constant { stiffness: km },
                MeshDamping::Constant(cm),
            ),
        )
        .load("pinion", 1, 4.0, 1.0)
        .load("gear", 2, 0.0, 2.0)
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(w, 3).unwrap()).unwrap();
    let sol = FixedPoint::new()
        .with_tolerance(1e-14)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{:?}", sol.termination);
    let wv = nalgebra::DVector::from_row_slice(&[r1, r2]);
    let kt = &k + km * &wv * wv.transpose();
    let dt = &d + cm * &wv * wv.transpose();
    for (order, f) in [
        (1usize, [Complex64::new(4.0, -1.0), Complex64::default()]),
        (2, [Complex64::default(), Complex64::new(0.0, -2.0)]),
    ] {
        let om = order as f64 * w;
        let z = DMatrix::from_fn(2, 2, |i, j| {
            Complex64::new(kt[(i, j)] - om * om * m[(i, j)], om * dt[(i, j)])
        });
        let x = z
            .lu()
            .solve(&nalgebra::DVector::from_row_slice(&f))
            .unwrap();
        for i in 0..2 {
            let got = sol.harmonic(i, order);
            assert!(
                (got - x[i]).norm() < 1e-12 * x.norm(),
                "order {order} dof {i}"
            );
        }
    }
}

/// An undamped resonance at a kept harmonic is a clear error, not NaN.
#[test]
fn undamped_resonance_is_an_error() {
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .element("spring", &[("x", 1.0)], LinearSpring::new(4.0, 0.0))
        .load("x", 1, 1.0, 0.0)
        .build()
        .unwrap();
    // ω_n = 2: harmonic 2 of Ω = 1 is resonant.
    let err = HarmonicBalance::new(&model, HarmonicBasis::new(1.0, 3).unwrap()).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(
            err,
            hbal::Error::SingularDynamicStiffness { harmonic: 2, .. }
        ),
        "{msg}"
    );
    assert!(msg.contains("harmonic 2"), "{msg}");
}

/// The FFT-based time series agrees with direct evaluation, also for many harmonics.
#[test]
fn time_series_matches_direct_evaluation() {
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .element("spring", &[("x", 1.0)], LinearSpring::new(3.0, 0.2))
        .load("x", 0, 0.5, 0.0)
        .load("x", 1, 1.0, 0.3)
        .load("x", 300, 0.2, -0.1)
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.1, 300).unwrap()).unwrap();
    let sol = FixedPoint::new().solve(&hb, &mut hb.workspace()).unwrap();
    for points in [601, 1024, 4096] {
        let series = sol.time_series(0, points);
        for j in (0..points).step_by(37) {
            let theta = std::f64::consts::TAU * j as f64 / points as f64;
            assert!((series[j] - sol.displacement(0, theta)).abs() < 1e-13);
        }
    }
    // Fewer points than 2H+1 use the direct sum.
    let coarse = sol.time_series(0, 100);
    assert!((coarse[7] - sol.displacement(0, std::f64::consts::TAU * 7.0 / 100.0)).abs() < 1e-13);
}
