//! Bad input gives an error that says what and where; never a panic.

use hbal::force::{Backlash, LinearSpring, MeshDamping, MeshProfile, MeshStiffness};
use hbal::{Error, FixedPoint, HarmonicBalance, HarmonicBasis, Model};
use nalgebra::DMatrix;

fn message(r: Result<Model, Error>) -> String {
    r.unwrap_err().to_string()
}

#[test]
fn model_errors_name_the_place() {
    let cases: Vec<(Result<Model, Error>, &str)> = vec![
        (Model::builder(&[]).mass_diagonal(&[]).build(), "no DOFs"),
        (
            Model::builder(&["a", "a"])
                .mass_diagonal(&[1.0, 1.0])
                .build(),
            "`a` appears twice",
        ),
        (Model::builder(&["a"]).build(), "no mass matrix"),
        (
            Model::builder(&["a"]).mass_diagonal(&[-1.0]).build(),
            "not symmetric positive definite",
        ),
        (
            Model::builder(&["a", "b"])
                .mass(DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]))
                .build(),
            "not symmetric",
        ),
        (
            Model::builder(&["a", "b"]).mass_diagonal(&[1.0]).build(),
            "expected 2 x 2",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .stiffness(DMatrix::from_element(1, 1, f64::NAN))
                .build(),
            "stiffness matrix: parameter `[0][0]` must be finite",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .load("b", 1, 1.0, 0.0)
                .build(),
            "unknown DOF `b`",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .load("a", 1, f64::INFINITY, 0.0)
                .build(),
            "parameter `cos` must be finite",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .element("spring", &[("c", 1.0)], LinearSpring::new(1.0, 0.0))
                .build(),
            "element `spring`: unknown DOF `c` (the model has: a)",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .element("spring", &[("a", 1.0)], LinearSpring::new(-1.0, 0.0))
                .build(),
            "element `spring`: parameter `k` must be finite and >= 0, got -1",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .element(
                    "gap",
                    &[("a", 1.0)],
                    Backlash::new(-0.1, MeshProfile::Constant { stiffness: 1.0 }),
                )
                .build(),
            "element `gap`: parameter `half_backlash` must be finite and >= 0",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .element(
                    "mesh",
                    &[("a", 1.0)],
                    MeshStiffness::new(
                        4,
                        MeshProfile::Rectangular {
                            one_tooth: 1.0,
                            two_tooth: 2.0,
                            contact_ratio: 2.5,
                        },
                        MeshDamping::Constant(0.0),
                    ),
                )
                .build(),
            "parameter `contact_ratio` must be in [1, 2]",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .element(
                    "mesh",
                    &[("a", 1.0)],
                    MeshStiffness::new(
                        0,
                        MeshProfile::Constant { stiffness: 1.0 },
                        MeshDamping::Constant(0.0),
                    ),
                )
                .build(),
            "parameter `teeth` must be an integer in 1..=65536",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .element(
                    "mesh",
                    &[("a", 1.0)],
                    MeshStiffness::new(
                        1,
                        MeshProfile::Constant { stiffness: 1.0 },
                        MeshDamping::Proportional(f64::NAN),
                    ),
                )
                .build(),
            "damping.proportional",
        ),
        (
            Model::builder(&["a"])
                .mass_diagonal(&[1.0])
                .element(
                    "spring",
                    &[("a", 1.0), ("a", 2.0)],
                    LinearSpring::new(1.0, 0.0),
                )
                .build(),
            "names DOF `a` twice",
        ),
    ];
    for (result, expected) in cases {
        let msg = message(result);
        assert!(
            msg.contains(expected),
            "`{msg}` does not contain `{expected}`"
        );
    }
}

/// The new laws and the element offset: every bad parameter names the element and the field.
#[test]
fn new_law_errors_name_element_and_field() {
    use hbal::force::{
        ForceLaw, Friction, GapContact, Jenkins, Offset, PolynomialSpring, QuadraticDamper, Stage,
        StopSpring,
    };
    let build = |law: Box<dyn ForceLaw>| {
        Model::builder(&["a"])
            .mass_diagonal(&[1.0])
            .element_boxed("el", &[("a", 1.0)], law)
            .build()
    };
    let stage = |from, stiffness| Stage { from, stiffness };
    let cases: Vec<(Box<dyn ForceLaw>, &str)> = vec![
        (
            Box::new(Offset::new(f64::NAN, GapContact::new(0.0, 1.0))),
            "element `el`: parameter `offset` must be finite, got NaN",
        ),
        (
            Box::new(Offset::new(0.1, GapContact::new(f64::INFINITY, 1.0))),
            "element `el`: parameter `gap` must be finite, got inf",
        ),
        (
            Box::new(GapContact::new(0.0, -1.0)),
            "element `el`: parameter `stiffness` must be finite and >= 0",
        ),
        (
            Box::new(GapContact::new(0.0, 1.0).with_contact_damping(-0.1)),
            "element `el`: parameter `contact_damping` must be finite and >= 0",
        ),
        (
            Box::new(GapContact::new(0.0, 1.0).with_teeth(0)),
            "element `el`: parameter `teeth` must be an integer in 1..=65536",
        ),
        (
            Box::new(StopSpring::new(vec![])),
            "element `el`: parameter `stages` must be a non-empty list",
        ),
        (
            Box::new(StopSpring::new(vec![stage(0.0, 400.0), stage(0.3, 50.0)])),
            "element `el`: parameter `stages[1].stiffness` must be >= stages[0].stiffness = 400 (a progressive spring",
        ),
        (
            Box::new(StopSpring::new(vec![stage(0.2, 1.0), stage(0.2, 2.0)])),
            "element `el`: parameter `stages[1].from` must be > stages[0].from = 0.2",
        ),
        (
            Box::new(StopSpring::new(vec![stage(-0.1, 1.0)])),
            "element `el`: parameter `stages[0].from` must be finite and >= 0, got -0.1",
        ),
        (
            Box::new(
                StopSpring::new(vec![stage(0.0, 1.0)])
                    .with_negative(vec![stage(0.0, 5.0), stage(0.1, 2.0)]),
            ),
            "element `el`: parameter `negative[1].stiffness` must be >= negative[0].stiffness = 5",
        ),
        (
            Box::new(StopSpring::new(vec![stage(0.0, 1.0)]).with_damping(-1.0)),
            "element `el`: parameter `damping` must be finite and >= 0",
        ),
        (
            Box::new(Friction::new(-0.5, 0.1)),
            "element `el`: parameter `limit` must be finite and >= 0, got -0.5",
        ),
        (
            Box::new(Friction::new(0.5, 0.0)),
            "element `el`: parameter `regularization` must be finite and > 0, got 0",
        ),
        (
            Box::new(Jenkins::new(-20.0, 1.0)),
            "element `el`: parameter `stiffness` must be finite and >= 0, got -20",
        ),
        (
            Box::new(Jenkins::new(20.0, -1.0)),
            "element `el`: parameter `limit` must be finite and >= 0, got -1",
        ),
        (
            Box::new(Offset::new(0.1, Jenkins::new(20.0, f64::INFINITY))),
            "element `el`: parameter `limit` must be finite and >= 0, got inf",
        ),
        (
            Box::new(Jenkins::new(20.0, 1.0).with_damping(f64::NAN)),
            "element `el`: parameter `damping` must be finite and >= 0, got NaN",
        ),
        (
            Box::new(QuadraticDamper::new(-2.0)),
            "element `el`: parameter `c` must be finite and >= 0",
        ),
        (
            Box::new(PolynomialSpring::new(vec![])),
            "element `el`: parameter `coefficients` must be a non-empty list",
        ),
        (
            Box::new(PolynomialSpring::new(vec![1.0, f64::NAN])),
            "element `el`: parameter `coefficients[1]` must be finite, got NaN",
        ),
    ];
    for (law, expected) in cases {
        let msg = message(build(law));
        assert!(
            msg.contains(expected),
            "`{msg}` does not contain `{expected}`"
        );
    }
}

#[test]
fn discretisation_errors() {
    assert!(matches!(
        HarmonicBasis::new(1.0, 8).unwrap().with_samples(16),
        Err(Error::TooFewSamples {
            harmonics: 8,
            samples: 16
        })
    ));
    assert!(HarmonicBasis::new(-1.0, 8)
        .unwrap_err()
        .to_string()
        .contains("omega"));
    assert!(HarmonicBasis::new(f64::NAN, 8).is_err());
    let model = Model::builder(&["a"])
        .mass_diagonal(&[1.0])
        .element("spring", &[("a", 1.0)], LinearSpring::new(1.0, 0.1))
        .load("a", 5, 1.0, 0.0)
        .build()
        .unwrap();
    let err = HarmonicBalance::new(&model, HarmonicBasis::new(1.0, 3).unwrap()).unwrap_err();
    assert!(
        err.to_string().contains("order 5 but only 3 harmonics"),
        "{err}"
    );
    // A free rigid-body mode under a static load: it would accelerate, no periodic solution.
    let free = Model::builder(&["a"])
        .mass_diagonal(&[1.0])
        .load("a", 0, 1.0, 0.0)
        .build()
        .unwrap();
    let err = HarmonicBalance::new(&free, HarmonicBasis::new(1.0, 3).unwrap()).unwrap_err();
    assert!(
        err.to_string().contains("static loads do not balance")
            && err.to_string().contains("net torque 1.0")
            && err.to_string().contains("rigid-body"),
        "{err}"
    );
}

#[test]
fn solver_option_errors() {
    assert!(FixedPoint::new()
        .with_gamma(1.0)
        .unwrap_err()
        .to_string()
        .contains("gamma"));
    assert!(FixedPoint::new().with_gamma(-0.1).is_err());
    assert!(FixedPoint::new().with_tolerance(f64::NAN).is_err());
    // Options set directly are validated at solve time.
    let model = Model::builder(&["a"])
        .mass_diagonal(&[1.0])
        .element("spring", &[("a", 1.0)], LinearSpring::new(1.0, 0.1))
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(2.0, 3).unwrap()).unwrap();
    let bad = FixedPoint {
        gamma: 2.0,
        ..FixedPoint::default()
    };
    assert!(bad.solve(&hb, &mut hb.workspace()).is_err());
    let wrong_len =
        FixedPoint::new().solve_from(&hb, &[Default::default(); 2], &mut hb.workspace());
    assert!(wrong_len
        .unwrap_err()
        .to_string()
        .contains("initial harmonics"));
}

/// A user law that returns NaN: the solve stops with a NonFinite termination naming the
/// element, and keeps the last finite iterate.
#[test]
fn non_finite_force_is_a_termination_not_a_nan() {
    #[derive(Debug, serde::Serialize, serde::Deserialize)]
    struct Sqrt;
    #[typetag::serde(name = "test_sqrt")]
    impl hbal::force::ForceLaw for Sqrt {
        fn force(&self, _t: f64, u: f64, _du: f64) -> f64 {
            u + u.sqrt() // NaN once u < 0
        }
        fn derivatives(&self, _t: f64, u: f64, _du: f64) -> (f64, f64) {
            (1.0 + 0.5 / u.sqrt(), 0.0)
        }
        fn linear_part(&self) -> hbal::force::LinearPart {
            hbal::force::LinearPart {
                stiffness: 1.0,
                ..Default::default()
            }
        }
    }
    let model = Model::builder(&["a"])
        .mass_diagonal(&[1.0])
        .damping(DMatrix::from_element(1, 1, 0.1))
        .element("root", &[("a", 1.0)], Sqrt)
        .load("a", 1, 1.0, 0.0)
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.5, 4).unwrap()).unwrap();
    let sol = FixedPoint::new().solve(&hb, &mut hb.workspace()).unwrap();
    match &sol.termination {
        hbal::Termination::NonFinite { what } => assert!(what.contains("root"), "{what}"),
        t => panic!("expected NonFinite, got {t:?}"),
    }
    assert!(sol
        .harmonics()
        .iter()
        .all(|q| q.re.is_finite() && q.im.is_finite()));
    assert!(sol.history.iter().all(|r| r.is_finite()));
}

/// The fixed point diverges when the mesh variation is strong near resonance: a termination,
/// not a hang or NaN.
#[test]
fn divergence_is_reported() {
    let case = hbal::catalog::TwoShaft::new(6000.0);
    let model = case.model().unwrap();
    let hb =
        HarmonicBalance::new(&model, HarmonicBasis::new(case.mesh_omega(), 32).unwrap()).unwrap();
    let sol = FixedPoint::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert_eq!(sol.termination, hbal::Termination::Diverged);
    assert!(sol.stats.iterations < 200);
    // Relaxation rescues it (the paper's damping factor γ).
    let sol = FixedPoint::new()
        .with_gamma(0.5)
        .unwrap()
        .with_max_iterations(1000)
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged());
}
