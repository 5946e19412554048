//! Every built-in law: derivatives against finite differences, linear parts, jumps, serde names.

use hbal::force::{
    check_derivatives, Backlash, CubicSpring, ForceLaw, LinearSpring, MeshDamping, MeshProfile,
    MeshStiffness,
};

/// Points away from kinks and stiffness jumps.
fn points() -> Vec<(f64, f64, f64)> {
    let mut p = Vec::new();
    for &theta in &[0.3, 1.1, 2.0, 4.4, 5.9] {
        for &u in &[-2.3, -0.4, 0.7, 1.9] {
            for &du in &[-1.5, 0.2, 3.0] {
                p.push((theta, u, du));
            }
        }
    }
    p
}

fn laws() -> Vec<Box<dyn ForceLaw>> {
    vec![
        Box::new(LinearSpring::new(3.0, 0.2)),
        Box::new(CubicSpring::new(1.0, 0.7)),
        Box::new(MeshStiffness::new(
            2,
            MeshProfile::Cosine {
                mean: 10.0,
                amplitude: 3.0,
            },
            MeshDamping::Proportional(0.01),
        )),
        Box::new(MeshStiffness::new(
            1,
            MeshProfile::Fourier {
                mean: 5.0,
                cos: vec![1.0, 0.5],
                sin: vec![0.2],
            },
            MeshDamping::Constant(0.3),
        )),
        Box::new(
            Backlash::new(
                0.1,
                MeshProfile::Cosine {
                    mean: 1.0,
                    amplitude: 0.2,
                },
            )
            .with_contact_damping(0.05),
        ),
    ]
}

#[test]
fn derivatives_match_finite_differences() {
    for law in laws() {
        let c = check_derivatives(law.as_ref(), &points());
        assert!(
            c.max_relative_error < 1e-6,
            "{law:?}: {} at {:?}",
            c.max_relative_error,
            c.worst_point
        );
    }
}

#[test]
fn derivative_check_catches_a_wrong_law() {
    #[derive(Debug, serde::Serialize, serde::Deserialize)]
    struct Wrong;
    #[typetag::serde(name = "test_wrong")]
    impl ForceLaw for Wrong {
        fn force(&self, _t: f64, u: f64, _du: f64) -> f64 {
            u * u
        }
        fn derivatives(&self, _t: f64, u: f64, _du: f64) -> (f64, f64) {
            (u, 0.0) // should be 2u
        }
    }
    assert!(check_derivatives(&Wrong, &points()).max_relative_error > 0.1);
}

#[test]
fn rectangular_mesh_values_mean_and_jumps() {
    let mesh = MeshStiffness::new(
        4,
        MeshProfile::Rectangular {
            one_tooth: 2.5e5,
            two_tooth: 5e5,
            contact_ratio: 1.5,
        },
        MeshDamping::Proportional(2e-6),
    );
    let lin = mesh.linear_part();
    assert_eq!(lin.stiffness, 3.75e5);
    assert!((lin.damping - 0.75).abs() < 1e-12);
    // The default linear part (average of the linearisation) agrees for this profile.
    let sampled: f64 = (0..4096)
        .map(|j| {
            mesh.derivatives(std::f64::consts::TAU * (j as f64 + 0.5) / 4096.0, 0.0, 0.0)
                .0
        })
        .sum::<f64>()
        / 4096.0;
    assert!((sampled - 3.75e5).abs() < 1e-6);
    let jumps = mesh.time_breakpoints();
    assert_eq!(jumps.len(), 8);
    for (j, t) in jumps.iter().enumerate() {
        assert!((t - std::f64::consts::TAU * j as f64 / 8.0).abs() < 1e-12);
    }
    // Batch evaluation equals pointwise evaluation.
    let theta: Vec<f64> = (0..64).map(|j| 0.1 * j as f64).collect();
    let u: Vec<f64> = theta.iter().map(|t| t.sin()).collect();
    let du: Vec<f64> = theta.iter().map(|t| t.cos()).collect();
    let mut out = vec![0.0; 64];
    mesh.force_batch(&theta, &u, &du, &mut out);
    for j in 0..64 {
        assert_eq!(out[j], mesh.force(theta[j], u[j], du[j]));
    }
}

/// Batch evaluation (with the cosine recurrence on equidistant angles) equals pointwise
/// evaluation for every built-in law, over several blocks of 64.
#[test]
fn batch_evaluation_matches_pointwise() {
    let n = 300;
    let uniform: Vec<f64> = (0..n)
        .map(|j| std::f64::consts::TAU * j as f64 / n as f64)
        .collect();
    let ragged: Vec<f64> = (0..n)
        .map(|j| 0.02 * j as f64 + 0.001 * (j as f64).sin())
        .collect();
    for theta in [uniform, ragged] {
        let u: Vec<f64> = theta.iter().map(|t| 2.5 * (1.3 * t).sin()).collect();
        let du: Vec<f64> = theta.iter().map(|t| (0.7 * t).cos()).collect();
        for law in laws() {
            let mut out = vec![0.0; n];
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            law.force_batch(&theta, &u, &du, &mut out);
            law.derivatives_batch(&theta, &u, &du, &mut a, &mut b);
            for j in 0..n {
                let f = law.force(theta[j], u[j], du[j]);
                let (da, db) = law.derivatives(theta[j], u[j], du[j]);
                assert!(
                    (out[j] - f).abs() <= 1e-13 * f.abs().max(1.0),
                    "{law:?} sample {j}"
                );
                assert!((a[j] - da).abs() <= 1e-13 * da.abs().max(1.0));
                assert!((b[j] - db).abs() <= 1e-13 * db.abs().max(1.0));
            }
        }
    }
}

#[test]
fn backlash_dead_zone() {
    let b = Backlash::new(1.0, MeshProfile::Constant { stiffness: 2.0 }).with_contact_damping(0.5);
    assert_eq!(b.force(0.0, 0.99, 7.0), 0.0);
    assert_eq!(b.force(0.0, 1.5, 0.0), 1.0);
    assert_eq!(b.force(0.0, -1.5, 1.0), -1.0 + 0.5);
    assert_eq!(b.derivatives(0.0, 0.0, 0.0), (0.0, 0.0));
    assert_eq!(b.derivatives(0.0, -3.0, 0.0), (2.0, 0.5));
    assert_eq!(b.linear_part().stiffness, 2.0);
}

#[test]
fn laws_round_trip_through_serde_with_stable_names() {
    for law in laws() {
        let json = serde_json::to_string(&law).unwrap();
        let back: Box<dyn ForceLaw> = serde_json::from_str(&json).unwrap();
        assert_eq!(format!("{law:?}"), format!("{back:?}"));
    }
    let law: Box<dyn ForceLaw> = serde_json::from_str(
        r#"{"type": "mesh_stiffness", "teeth": 4,
            "profile": {"shape": "rectangular", "one_tooth": 2.5e5, "two_tooth": 5e5, "contact_ratio": 1.5},
            "damping": {"proportional": 5.16e-6}}"#,
    )
    .unwrap();
    assert_eq!(law.force(0.1, 1.0, 0.0), 5e5);
    let err = serde_json::from_str::<Box<dyn ForceLaw>>(r#"{"type": "linear_sprung", "k": 1}"#)
        .unwrap_err()
        .to_string();
    assert!(err.contains("linear_sprung"), "{err}");
}
