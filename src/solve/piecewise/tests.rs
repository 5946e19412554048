use super::*;
use crate::catalog::TwoShaft;
use crate::force::{LinearSpring, MeshDamping, MeshProfile, MeshStiffness, Offset};

/// A 2-DOF chain with one rectangular mesh and a grounded spring, loads at orders 0 and 2;
/// with `preload`, both elements have offsets (their forces at rest `-k u0` are static loads,
/// the mesh's jumping with its stiffness).
fn chain(contact_ratio: f64, preload: bool) -> Model {
    let mesh = MeshStiffness::new(
        3,
        MeshProfile::Rectangular {
            one_tooth: 2e5,
            two_tooth: 3.5e5,
            contact_ratio,
        },
        MeshDamping::Proportional(4e-6),
    );
    let ground = LinearSpring::new(1e5, 0.5);
    let builder = Model::builder(&["a", "b"])
        .mass_diagonal(&[1e-3, 2e-3])
        .stiffness_triplets(&[(0, 0, 4e5)])
        .damping_triplets(&[(0, 0, 2.0), (1, 1, 1.0)]);
    let builder = if preload {
        builder
            .element("mesh", &[("a", 1.0), ("b", -0.5)], Offset::new(-2e-5, mesh))
            .element("ground", &[("b", 1.0)], Offset::new(3e-5, ground))
    } else {
        builder
            .element("mesh", &[("a", 1.0), ("b", -0.5)], mesh)
            .element("ground", &[("b", 1.0)], ground)
    };
    builder
        .load("a", 0, 5.0, 0.0)
        .load("b", 2, 0.7, -0.2)
        .build()
        .unwrap()
}

#[test]
fn a_time_invariant_scene_is_the_linear_frequency_response() {
    // Constant mesh stiffness: one piece, Q_k = Z(kΩ)⁻¹ F_k exactly.
    let model = Model::builder(&["x"])
        .mass_diagonal(&[2.0])
        .damping_triplets(&[(0, 0, 0.3)])
        .element(
            "mesh",
            &[("x", 1.0)],
            MeshStiffness::new(
                2,
                MeshProfile::Constant { stiffness: 50.0 },
                MeshDamping::Constant(0.1),
            ),
        )
        .load("x", 0, 1.0, 0.0)
        .load("x", 3, 0.5, 0.25)
        .build()
        .unwrap();
    let omega = 1.7;
    let basis = HarmonicBasis::new(omega, 8).unwrap();
    let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
    let z = |w: f64| Complex64::new(50.0 - 2.0 * w * w, 0.4 * w);
    let want0 = 1.0 / 50.0;
    let want3 = Complex64::new(0.5, -0.25) / z(3.0 * omega);
    let got = exact.solution.harmonics();
    assert!((got[0].re - want0).abs() < 1e-15 && got[0].im.abs() < 1e-15);
    assert!(
        (got[3] - want3).norm() < 1e-14 * want3.norm(),
        "{} against {want3}",
        got[3]
    );
    for (k, q) in got.iter().enumerate() {
        if k != 0 && k != 3 {
            assert!(q.norm() < 1e-15, "harmonic {k}: {q}");
        }
    }
    assert!(exact.estimate.relative < 1e-14);
}

#[test]
fn harmonic_balance_converges_to_the_exact_harmonics() {
    // Two independent methods: harmonic balance (band-limited stiffness, tail correction)
    // approaches the exact harmonics as H grows (1.9e-4, 1.1e-7, 9.1e-9 at H = 16, 32, 64).
    let model = chain(1.6, false);
    let omega = 3000.0;
    let reference = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(omega, 64).unwrap())
        .unwrap();
    let mut last = f64::INFINITY;
    for h in [16, 32, 64] {
        let basis = HarmonicBasis::new(omega, h).unwrap();
        let hb = HarmonicBalance::new(&model, basis).unwrap();
        let mut ws = hb.workspace();
        let newton = crate::Newton::new().with_tolerance(1e-12).unwrap();
        let sol = newton.solve_from_option(&hb, None, &mut ws).unwrap();
        let err =
            crate::compare::relative_error(sol.harmonics(), reference.solution.harmonics(), 2, 8);
        eprintln!("H = {h}: {err:.2e}");
        assert!(err < last, "H = {h}: {err:.2e} after {last:.2e}");
        last = err;
    }
    assert!(
        last < 3e-8,
        "HB at H = 64 against the exact harmonics: {last:.2e}"
    );
}

#[test]
fn the_mean_is_the_static_deflection_through_each_piece() {
    // At 6 rpm the mesh period is ~7700 natural periods long: the response is the static
    // deflection L0/k of each piece almost everywhere.
    let shaft = TwoShaft::new(6.0);
    let basis = HarmonicBasis::new(shaft.mesh_omega(), 4).unwrap();
    let exact = PiecewiseExact::new()
        .solve_exact(&shaft.model().unwrap(), &basis)
        .unwrap();
    let (k1, k2, eps) = (
        TwoShaft::ONE_TOOTH,
        TwoShaft::TWO_TOOTH,
        TwoShaft::CONTACT_RATIO,
    );
    let mean = TwoShaft::L0 * ((eps - 1.0) / k2 + (2.0 - eps) / k1);
    let got = exact.solution.harmonic(0, 0).re;
    assert!((got - mean).abs() < 1e-3 * mean, "{got:e} against {mean:e}");
}

#[test]
fn scenes_it_cannot_solve_exactly_are_refused_by_name() {
    let model = crate::catalog::Duffing::default().model().unwrap();
    let basis = HarmonicBasis::new(1.0, 8).unwrap();
    let err = PiecewiseExact::new()
        .solve_exact(&model, &basis)
        .unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("element `") && text.contains("piecewise_exact"),
        "{text}"
    );
    // An undamped piece resonating at a load's order.
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .stiffness_triplets(&[(0, 0, 4.0)])
        .load("x", 1, 1.0, 0.0)
        .build()
        .unwrap();
    let err = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(2.0, 4).unwrap())
        .unwrap_err();
    assert!(
        matches!(err, Error::SingularDynamicStiffness { harmonic: 1, .. }),
        "{err}"
    );
}

#[test]
fn preloaded_elements_against_the_time_domain() {
    // Offsets make each element's force at rest a static load, the mesh's jumping with its
    // stiffness; the time domain integrates the laws themselves.
    let model = chain(1.6, true);
    let omega = 3000.0;
    let exact = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(omega, 16).unwrap())
        .unwrap();
    let td = crate::timesim::TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        samples: 4096,
        ..crate::timesim::TimeSimulation::default()
    }
    .run(&model, omega)
    .unwrap();
    let err = crate::compare::relative_error(exact.solution.harmonics(), &td.harmonics, 2, 16);
    let without = PiecewiseExact::new()
        .solve_exact(&chain(1.6, false), &HarmonicBasis::new(omega, 16).unwrap())
        .unwrap();
    let moved = crate::compare::relative_error(without.solution.harmonics(), &td.harmonics, 2, 16);
    eprintln!("preloaded: {err:.2e} against the time domain ({moved:.2e} without the preloads)");
    assert!(err < 1e-9 && moved > 1e-2, "{err:.2e}, {moved:.2e}");
}
