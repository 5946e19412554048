use super::*;
use crate::catalog::TwoShaft;
use crate::force::{LinearSpring, MeshDamping, MeshProfile, MeshStiffness, Offset};

/// A 2-DOF chain with one rectangular mesh and a grounded spring, loads at orders 0 and 2;
/// with `preload`, both elements have offsets (their forces at rest `-k u0` are static loads,
/// the mesh's jumping with its stiffness).
fn chain(contact_ratio: f64, preload: bool) -> Model {
    chain_in_time_unit(contact_ratio, preload, 1.0)
}

/// [`chain`] with time measured in units `c` times smaller: `M c²`, `D c` (the same motion at
/// `Ω / c`).
pub(super) fn chain_in_time_unit(contact_ratio: f64, preload: bool, c: f64) -> Model {
    let mesh = MeshStiffness::new(
        3,
        MeshProfile::Rectangular {
            one_tooth: 2e5,
            two_tooth: 3.5e5,
            contact_ratio,
        },
        MeshDamping::Proportional(4e-6 * c),
    );
    let ground = LinearSpring::new(1e5, 0.5 * c);
    let builder = Model::builder(&["a", "b"])
        .mass_diagonal(&[1e-3 * c * c, 2e-3 * c * c])
        .stiffness_triplets(&[(0, 0, 4e5)])
        .damping_triplets(&[(0, 0, 2.0 * c), (1, 1, 1.0 * c)]);
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
        let basis = HarmonicBasis::new(omega, h)
            .unwrap()
            .with_tail_correction(true);
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

#[test]
fn a_model_that_floats_free_has_its_rigid_motion_separated() {
    // Two inertias joined only by a mesh, the mean torques balanced, an order-1 torque on one:
    // the rigid body swings with it, the mesh twists.
    let free = |profile: MeshProfile, mean_b: f64| {
        Model::builder(&["a", "b"])
            .mass_diagonal(&[1e-3, 2e-3])
            .element(
                "mesh",
                &[("a", 1.0), ("b", -1.0)],
                MeshStiffness::new(2, profile, MeshDamping::Proportional(4e-6)),
            )
            .load("a", 0, 5.0, 0.0)
            .load("b", 0, mean_b, 0.0)
            .load("a", 1, 0.5, 0.2)
            .build()
            .unwrap()
    };
    let omega = 3000.0;
    let newton = |model: &Model, h: usize| {
        let basis = HarmonicBasis::new(omega, h)
            .unwrap()
            .with_tail_correction(true);
        let hb = HarmonicBalance::new(model, basis).unwrap();
        crate::Newton::new()
            .with_tolerance(1e-12)
            .unwrap()
            .solve_from_option(&hb, None, &mut hb.workspace())
            .unwrap()
    };
    // Constant stiffness: harmonic balance is exact, and so the same mean rigid position
    // (zero) and rigid swing.
    let constant = free(MeshProfile::Constant { stiffness: 3e5 }, -5.0);
    let exact = PiecewiseExact::new()
        .solve_exact(&constant, &HarmonicBasis::new(omega, 4).unwrap())
        .unwrap();
    let hb = newton(&constant, 4);
    let err = crate::compare::relative_error(exact.solution.harmonics(), hb.harmonics(), 2, 4);
    assert!(err < 1e-12, "{err:.2e}");
    assert_eq!((exact.multipliers.len(), exact.neutral), (2, 2));
    // Rectangular stiffness: harmonic balance at H = 64 approaches the exact harmonics.
    let rectangular = free(
        MeshProfile::Rectangular {
            one_tooth: 2e5,
            two_tooth: 3.5e5,
            contact_ratio: 1.4,
        },
        -5.0,
    );
    let exact = PiecewiseExact::new()
        .solve_exact(&rectangular, &HarmonicBasis::new(omega, 8).unwrap())
        .unwrap();
    let err = crate::compare::relative_error(
        exact.solution.harmonics(),
        newton(&rectangular, 64).harmonics(),
        2,
        8,
    );
    eprintln!("free-free, rectangular: HB at H = 64 {err:.2e} from the exact harmonics");
    assert!(err < 1e-7, "{err:.2e}");
    assert!(exact.multipliers[0].norm() < 1.0 && exact.neutral == 2);
    // Mean loads that do not balance: the body accelerates away, named.
    let err =
        PiecewiseExact::check(&free(MeshProfile::Constant { stiffness: 3e5 }, -4.0)).unwrap_err();
    assert!(matches!(err, Error::UnbalancedStaticLoad { .. }), "{err}");
    // Grounded by a spring there is no rigid body.
    let grounded = Model::builder(&["a", "b"])
        .mass_diagonal(&[1e-3, 2e-3])
        .element("ground", &[("a", 1.0)], LinearSpring::new(1e3, 0.0))
        .element(
            "mesh",
            &[("a", 1.0), ("b", -1.0)],
            LinearSpring::new(3e5, 1.0),
        )
        .load("a", 0, 5.0, 0.0)
        .build()
        .unwrap();
    let exact = PiecewiseExact::new()
        .solve_exact(&grounded, &HarmonicBasis::new(omega, 4).unwrap())
        .unwrap();
    assert_eq!((exact.multipliers.len(), exact.neutral), (4, 0));
}

#[test]
fn a_period_multiple_holds_the_same_orders() {
    // With ν = 2 harmonic j is order j/2: the even harmonics are the ν = 1 solution's, the odd
    // ones (half orders a linear scene does not excite) are zero.
    let model = chain(1.6, false);
    let omega = 3000.0;
    let one = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(omega, 8).unwrap())
        .unwrap();
    let basis = HarmonicBasis::new(omega, 16)
        .unwrap()
        .with_subharmonic(2)
        .unwrap();
    let two = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
    let (a, b) = (one.solution.harmonics(), two.solution.harmonics());
    for j in 0..=16 {
        for i in 0..2 {
            let got = b[j * 2 + i];
            let want = if j % 2 == 0 {
                a[(j / 2) * 2 + i]
            } else {
                Complex64::new(0.0, 0.0)
            };
            assert!(
                (got - want).norm() <= 1e-13 * a[i].norm(),
                "harmonic {j}, dof {i}: {got} against {want}"
            );
        }
    }
    assert_eq!(two.estimate.reference_harmonics % 2, 0);
    // A singular Z is named at the basis's harmonic: order 1 is harmonic 2.
    let undamped = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .stiffness_triplets(&[(0, 0, 4.0)])
        .load("x", 1, 1.0, 0.0)
        .build()
        .unwrap();
    let basis = HarmonicBasis::new(2.0, 8)
        .unwrap()
        .with_subharmonic(2)
        .unwrap();
    let err = PiecewiseExact::new()
        .solve_exact(&undamped, &basis)
        .unwrap_err();
    assert!(
        matches!(err, Error::SingularDynamicStiffness { harmonic: 2, .. }),
        "{err}"
    );
}

#[test]
fn an_undamped_scene_off_resonance_is_its_frequency_response() {
    // No damping: the multipliers lie on the unit circle (not at 1), I - Φ is regular and the
    // harmonics are Z(kΩ)⁻¹ F_k.
    let model = Model::builder(&["x"])
        .mass_diagonal(&[2.0])
        .stiffness_triplets(&[(0, 0, 50.0)])
        .load("x", 1, 1.0, 0.0)
        .load("x", 3, 0.5, 0.25)
        .build()
        .unwrap();
    let omega = 1.7;
    let exact = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(omega, 4).unwrap())
        .unwrap();
    let got = exact.solution.harmonics();
    let want1 = 1.0 / (50.0 - 2.0 * omega * omega);
    let want3 = Complex64::new(0.5, -0.25) / (50.0 - 2.0 * 9.0 * omega * omega);
    assert!((got[1].re - want1).abs() < 1e-12 * want1.abs() && got[1].im.abs() < 1e-15);
    assert!((got[3] - want3).norm() < 1e-12 * want3.norm(), "{}", got[3]);
    for mu in &exact.multipliers {
        assert!((mu.norm() - 1.0).abs() < 1e-12, "{mu}");
    }
}

#[test]
fn two_meshes_with_their_own_teeth_and_phases_against_the_time_domain() {
    // Breakpoints of two meshes (3 and 5 cycles per period, phases 0.7 and 1.9 rad)
    // interleave into 16 pieces of 4 configurations.
    let mesh = |teeth, phase| {
        MeshStiffness::new(
            teeth,
            MeshProfile::Rectangular {
                one_tooth: 2e5,
                two_tooth: 3.5e5,
                contact_ratio: 1.45,
            },
            MeshDamping::Proportional(4e-6),
        )
        .with_phase(phase)
    };
    let model = Model::builder(&["a", "b", "c"])
        .mass_diagonal(&[1e-3, 2e-3, 1.5e-3])
        .stiffness_triplets(&[(0, 0, 4e5)])
        .damping_triplets(&[(0, 0, 2.0), (2, 2, 1.0)])
        .element("first", &[("a", 1.0), ("b", -0.5)], mesh(3, 0.7))
        .element("second", &[("b", 1.0), ("c", -0.8)], mesh(5, 1.9))
        .element("ground", &[("c", 1.0)], LinearSpring::new(1e5, 0.5))
        .load("a", 0, 5.0, 0.0)
        .load("c", 1, 0.7, -0.2)
        .build()
        .unwrap();
    let omega = 1500.0;
    let schedule = Schedule::new(&model, omega).unwrap();
    assert_eq!(
        (schedule.pieces.len(), schedule.configurations.len()),
        (16, 4)
    );
    let exact = PiecewiseExact::new()
        .solve_exact(&model, &HarmonicBasis::new(omega, 16).unwrap())
        .unwrap();
    let td = crate::timesim::TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        samples: 16384,
        ..crate::timesim::TimeSimulation::default()
    }
    .run(&model, omega)
    .unwrap();
    let err = crate::compare::relative_error(exact.solution.harmonics(), &td.harmonics, 3, 16);
    eprintln!("two meshes: {err:.2e} against the time domain");
    assert!(err < 1e-9, "{err:.2e}");
}
