//! Every built-in law: derivatives against finite differences, linear parts, jumps, serde names.

use hbal::force::{
    check_derivatives, Backlash, ContactState, CubicSpring, ForceLaw, Friction, GapContact,
    LinearSpring, MeshDamping, MeshProfile, MeshStiffness, Offset, PolynomialSpring,
    QuadraticDamper, Stage, StopSpring,
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
        Box::new(
            GapContact::with_profile(
                0.1,
                MeshProfile::Cosine {
                    mean: 2.0,
                    amplitude: 0.5,
                },
            )
            .with_teeth(2)
            .with_contact_damping(0.3),
        ),
        Box::new(GapContact::new(-0.2, 5.0)),
        Box::new(StopSpring::new(vec![
            Stage {
                from: 0.2,
                stiffness: 1.0,
            },
            Stage {
                from: 1.0,
                stiffness: 4.0,
            },
            Stage {
                from: 2.0,
                stiffness: 9.0,
            },
        ])),
        Box::new(
            StopSpring::new(vec![Stage {
                from: 0.0,
                stiffness: 2.0,
            }])
            .with_negative(vec![
                Stage {
                    from: 0.3,
                    stiffness: 0.5,
                },
                Stage {
                    from: 1.5,
                    stiffness: 7.0,
                },
            ])
            .with_damping(0.4),
        ),
        Box::new(Friction::new(1.5, 0.5)),
        Box::new(QuadraticDamper::new(0.8)),
        Box::new(PolynomialSpring::new(vec![1.0, -0.5, 0.3, 0.1])),
        Box::new(Offset::new(
            0.25,
            Backlash::new(0.1, MeshProfile::Constant { stiffness: 3.0 }),
        )),
        Box::new(Offset::new(
            -0.3,
            GapContact::with_profile(
                0.2,
                MeshProfile::Fourier {
                    mean: 4.0,
                    cos: vec![1.0],
                    sin: vec![0.5],
                },
            )
            .with_contact_damping(0.1),
        )),
        Box::new(Offset::new(0.4, CubicSpring::new(1.0, 2.0))),
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

#[test]
fn gap_contact_is_one_sided() {
    let c = GapContact::new(1.0, 100.0).with_contact_damping(0.5);
    assert_eq!(c.force(0.0, 0.999, 3.0), 0.0);
    assert_eq!(c.force(0.0, -5.0, 3.0), 0.0);
    assert!((c.force(0.0, 1.5, -2.0) - (50.0 - 1.0)).abs() < 1e-12);
    assert_eq!(c.derivatives(0.0, 0.5, 1.0), (0.0, 0.0));
    assert_eq!(c.derivatives(0.0, 1.5, 1.0), (100.0, 0.5));
    assert_eq!(c.kinks(), vec![1.0]);
    // Open at rest; a preload (negative gap) is closed at rest: f = k (u - g), offset -k g.
    assert_eq!(c.linear_part(), Default::default());
    let pre = GapContact::new(-0.01, 100.0);
    let lin = pre.linear_part();
    assert_eq!((lin.stiffness, lin.offset), (100.0, 1.0));
    assert_eq!(pre.force(0.0, 0.0, 0.0), 1.0);
    let forced = c.clone().with_linearize(ContactState::Closed).linear_part();
    assert_eq!(
        (forced.stiffness, forced.damping, forced.offset),
        (100.0, 0.5, -100.0)
    );
    let open = pre.with_linearize(ContactState::Open).linear_part();
    assert_eq!(open.stiffness, 0.0);
    // A time-varying stiffness declares its order; a constant one does not.
    assert_eq!(c.time_order(), None);
    let varying = GapContact::with_profile(
        0.0,
        MeshProfile::Cosine {
            mean: 1.0,
            amplitude: 0.1,
        },
    )
    .with_teeth(3);
    assert_eq!(varying.time_order(), Some(3));
    // A plain number in a scene file is a constant stiffness.
    let law: Box<dyn ForceLaw> =
        serde_json::from_str(r#"{"type": "gap_contact", "gap": 1, "stiffness": 100}"#).unwrap();
    assert_eq!(law.force(0.0, 1.5, 0.0), 50.0);
    let err = serde_json::from_str::<Box<dyn ForceLaw>>(
        r#"{"type": "gap_contact", "gap": 1, "stiffness": {"shape": "cosine", "mean": 1, "amplitud": 0.1}}"#,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("unknown field `amplitud`"), "{err}");
}

#[test]
fn stop_spring_stages_and_sides() {
    let s = StopSpring::new(vec![
        Stage {
            from: 0.1,
            stiffness: 50.0,
        },
        Stage {
            from: 0.3,
            stiffness: 400.0,
        },
    ])
    .with_negative(vec![Stage {
        from: 0.2,
        stiffness: 80.0,
    }]);
    // Continuous through every stage start, free play around 0.
    for (u, f) in [
        (0.05, 0.0),
        (0.1, 0.0),
        (0.2, 5.0),
        (0.3, 10.0),
        (0.5, 10.0 + 80.0),
        (-0.15, 0.0),
        (-0.2, 0.0),
        (-0.7, -40.0),
    ] {
        assert!((s.force(0.0, u, 0.0) - f).abs() < 1e-12, "f({u})");
    }
    assert_eq!(s.derivatives(0.0, 0.2, 1.0).0, 50.0);
    assert_eq!(s.derivatives(0.0, 0.31, 1.0).0, 400.0);
    assert_eq!(s.derivatives(0.0, -0.31, 1.0).0, 80.0);
    assert_eq!(s.derivatives(0.0, 0.0, 1.0).0, 0.0);
    assert_eq!(s.kinks(), vec![-0.2, 0.1, 0.3]);
    assert_eq!(s.linear_part().stiffness, 65.0);
    // Both sides engaged from 0: one kink there unless the stiffnesses agree.
    let odd = StopSpring::new(vec![
        Stage {
            from: 0.0,
            stiffness: 2.0,
        },
        Stage {
            from: 1.0,
            stiffness: 3.0,
        },
    ]);
    assert_eq!(odd.kinks(), vec![-1.0, 1.0]);
    let bent = odd.clone().with_negative(vec![Stage {
        from: 0.0,
        stiffness: 1.0,
    }]);
    assert_eq!(bent.kinks(), vec![0.0, 1.0]);
}

#[test]
fn friction_damper_polynomial_values() {
    let f = Friction::new(3.0, 0.01);
    assert!((f.force(0.0, 9.0, 1.0) - 3.0).abs() < 1e-12);
    assert!((f.force(0.0, 9.0, -1.0) + 3.0).abs() < 1e-12);
    assert_eq!(f.force(0.0, 9.0, 0.0), 0.0);
    assert_eq!(f.linear_part(), Default::default());
    let d = QuadraticDamper::new(0.5);
    assert_eq!(d.force(0.0, 1.0, 4.0), 8.0);
    assert_eq!(d.force(0.0, 1.0, -4.0), -8.0);
    let p = PolynomialSpring::new(vec![2.0, 0.0, -1.0]);
    assert_eq!(p.force(0.0, 3.0, 5.0), 6.0 - 27.0);
    assert_eq!(p.derivatives(0.0, 3.0, 5.0), (2.0 - 27.0, 0.0));
}

#[test]
fn offset_shifts_the_law_and_everything_it_declares() {
    let inner = Backlash::new(
        0.1,
        MeshProfile::Rectangular {
            one_tooth: 1.0,
            two_tooth: 2.0,
            contact_ratio: 1.5,
        },
    )
    .with_teeth(3);
    let shifted = Offset::new(0.5, inner.clone());
    for &(t, u, v) in &[(0.1, 0.9, 0.3), (2.0, 0.2, -1.0), (4.0, 0.45, 2.0)] {
        assert_eq!(shifted.force(t, u, v), inner.force(t, u - 0.5, v));
        assert_eq!(
            shifted.derivatives(t, u, v),
            inner.derivatives(t, u - 0.5, v)
        );
    }
    assert_eq!(shifted.kinks(), vec![0.4, 0.6]);
    let (a, b) = (inner.linear_part(), shifted.linear_part());
    assert_eq!((a.stiffness, a.damping), (b.stiffness, b.damping));
    assert!((b.offset - (a.offset - a.stiffness * 0.5)).abs() < 1e-15);
    assert_eq!(shifted.time_breakpoints(), inner.time_breakpoints());
    assert_eq!(shifted.time_order(), Some(3));
    // The band-limited copy keeps the offset.
    let band = shifted
        .band_limited(64, 10)
        .expect("a jumping profile is band-limited");
    let inner_band = inner.band_limited(64, 10).unwrap();
    let theta = std::f64::consts::TAU * 5.0 / 64.0;
    assert_eq!(
        band.force(theta, 0.9, 0.0),
        inner_band.force(theta, 0.4, 0.0)
    );
    // A linear spring stays linear time-invariant, with the static force in its offset.
    let spring = Offset::new(0.02, LinearSpring::new(100.0, 1.0));
    assert!(spring.is_linear_time_invariant());
    assert_eq!(spring.linear_part().offset, -2.0);
    // Validation names the field.
    let err = Offset::new(f64::NAN, LinearSpring::new(1.0, 0.0))
        .validate("element `s`")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("element `s`: parameter `offset` must be finite"),
        "{err}"
    );
}
