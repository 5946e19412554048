//! Free-free models (no spring to ground): the static part is solved in the complement of the
//! rigid-body modes with the mean rigid angle `Rᵀ M q_0 = 0`, harmonics `k >= 1` as usual.
//! Checked against the closed-form linear solution, against the same model held by a very
//! soft ground spring, between the full and condensed formulations, and for the clear error
//! on unbalanced static loads.

use crate::common;

use hbal::force::{Backlash, LinearSpring, MeshDamping, MeshProfile, MeshStiffness};
use hbal::harmonic::from_cos_sin;
use hbal::nalgebra::{DMatrix, DVector};
use hbal::num_complex::Complex64;
use hbal::{Error, FixedPoint, Formulation, HarmonicBalance, HarmonicBasis, Model, Newton};

fn newton(hb: &HarmonicBalance) -> hbal::Solution {
    let sol = Newton::new()
        .with_tolerance(1e-13)
        .unwrap()
        .solve(hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    sol
}

/// Three inertias on two shafts, free-free: drive torque +T on `a`, load -T on `c`, and a
/// first-order torque on `a`. Harmonic 0: the twists are T/k1 and T/k2 and the mean rigid
/// angle Σ J_i q_i is zero; harmonic 1 is the 3×3 complex solve `Z_1 Q_1 = F_1`.
#[test]
fn linear_three_inertia_chain_equals_the_closed_form() {
    let (j, k1, k2, c1, c2, t) = ([0.1, 0.2, 0.4], 1e4, 2e4, 2.0, 3.0, 50.0);
    let (fc, fs) = (5.0, 2.0);
    let model = Model::builder(&["a", "b", "c"])
        .mass_diagonal(&j)
        .element("s1", &[("a", 1.0), ("b", -1.0)], LinearSpring::new(k1, c1))
        .element("s2", &[("b", 1.0), ("c", -1.0)], LinearSpring::new(k2, c2))
        .load("a", 0, t, 0.0)
        .load("c", 0, -t, 0.0)
        .load("a", 1, fc, fs)
        .build()
        .unwrap();
    let omega = 120.0;
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(omega, 2).unwrap()).unwrap();
    let rigid = hb.rigid_modes().expect("one rigid-body mode");
    assert_eq!(rigid.len(), 1);
    for sol in [
        FixedPoint::new().solve(&hb, &mut hb.workspace()).unwrap(),
        newton(&hb),
    ] {
        assert!(sol.is_converged(), "{}", sol.termination);
        let q0: Vec<f64> = (0..3).map(|i| sol.harmonic(i, 0).re).collect();
        assert!((q0[0] - q0[1] - t / k1).abs() < 1e-12 * t / k1, "{q0:?}");
        assert!((q0[1] - q0[2] - t / k2).abs() < 1e-12 * t / k2, "{q0:?}");
        let mean: f64 = (0..3).map(|i| j[i] * q0[i]).sum();
        assert!(mean.abs() < 1e-14 * t / k1, "mean rigid angle {mean:e}");
        // Harmonic 1.
        let kk = [[k1, -k1, 0.0], [-k1, k1 + k2, -k2], [0.0, -k2, k2]];
        let dd = [[c1, -c1, 0.0], [-c1, c1 + c2, -c2], [0.0, -c2, c2]];
        let z = DMatrix::from_fn(3, 3, |r, c| {
            let m = if r == c { j[r] } else { 0.0 };
            Complex64::new(kk[r][c] - omega * omega * m, omega * dd[r][c])
        });
        let f = DVector::from_vec(vec![from_cos_sin(fc, fs), 0.0.into(), 0.0.into()]);
        let q1 = z.lu().solve(&f).unwrap();
        for i in 0..3 {
            let d = (sol.harmonic(i, 1) - q1[i]).norm();
            assert!(d < 1e-12 * q1.camax(), "dof {i}: {d:e}");
        }
    }
}

/// A 7-DOF free-free drivetrain: engine, flywheel, input shaft, gear 1 | gear 2, output,
/// wheel; a mesh (time-varying stiffness) and a backlash on the same mesh coordinate, a
/// clutch backlash; engine torque 20 N m balanced by the wheel (`ground` adds a spring to
/// ground on the wheel, `wheel_load` its mean torque).
fn drivetrain(ground: f64, wheel_load: f64) -> Model {
    let names = ["engine", "flywheel", "shaft", "g1", "g2", "out", "wheel"];
    let inertia = [0.2, 0.5, 0.01, 0.002, 0.004, 0.02, 1.0];
    let mut k = DMatrix::zeros(7, 7);
    let mut spring = |i: usize, j: usize, c: f64| {
        k[(i, i)] += c;
        k[(j, j)] += c;
        k[(i, j)] -= c;
        k[(j, i)] -= c;
    };
    spring(0, 1, 2e4);
    spring(1, 2, 5e3);
    spring(2, 3, 8e3);
    spring(4, 5, 6e3);
    spring(5, 6, 3e3);
    let d = &k * 2e-4;
    k[(6, 6)] += ground;
    let profile = MeshProfile::Rectangular {
        one_tooth: 2e5,
        two_tooth: 3e5,
        contact_ratio: 1.4,
    };
    let (r1, r2) = (0.03, 0.05);
    Model::builder(&names)
        .mass_diagonal(&inertia)
        .stiffness(k)
        .damping(d)
        .element(
            "mesh",
            &[("g1", r1), ("g2", r2)],
            MeshStiffness::new(1, profile, MeshDamping::Constant(20.0)),
        )
        .element(
            "backlash",
            &[("g1", -r1), ("g2", -r2)],
            Backlash::new(1e-5, MeshProfile::Constant { stiffness: 1e4 }),
        )
        .element(
            "clutch",
            &[("shaft", 2.0), ("flywheel", -2.0)],
            Backlash::new(0.01, MeshProfile::Constant { stiffness: 500.0 }),
        )
        .load("engine", 0, 20.0, 0.0)
        .load("engine", 1, 30.0, 10.0)
        .load("wheel", 0, wheel_load, 0.0)
        .build()
        .unwrap()
}

/// The balancing wheel torque: the mesh pushes both gears, so the rigid mode turns the wheel
/// by `-r1/r2` per radian of the engine and the wheel's mean torque is `+20 r2/r1`.
const BALANCED: f64 = 20.0 * 0.05 / 0.03;

/// Against the same model held by a ground spring of 1e-9 of the shaft stiffness: the
/// harmonics k >= 1 and the static twist (Q_0 without its rigid part) agree to 1e-6.
#[test]
fn backlash_drivetrain_equals_a_softly_grounded_one() {
    let basis = HarmonicBasis::new(300.0, 24).unwrap();
    let free_model = drivetrain(0.0, BALANCED);
    let free_hb = HarmonicBalance::new(&free_model, basis).unwrap();
    let free = newton(&free_hb);
    let soft_model = drivetrain(3e3 * 1e-9, BALANCED);
    let soft_hb = HarmonicBalance::new(&soft_model, basis).unwrap();
    assert!(soft_hb.rigid_modes().is_none());
    let soft = newton(&soft_hb);
    let rigid = free_hb.rigid_modes().unwrap();
    assert_eq!(rigid.len(), 1);
    let (r, mr) = (rigid.modes(), rigid.mass_modes());
    // The rigid mode: engine..g1 turn together, g2..wheel by -r1/r2.
    assert!((r[(6, 0)] / r[(0, 0)] + 0.6).abs() < 1e-12);
    let n = 7;
    let q0 = |s: &hbal::Solution| DVector::from_fn(n, |i, _| s.harmonic(i, 0).re);
    let (qf, qs) = (q0(&free), q0(&soft));
    assert!(mr.column(0).dot(&qf).abs() < 1e-13 * qf.amax());
    let twist = &qs - r.column(0) * mr.column(0).dot(&qs);
    let d0 = (&twist - &qf).amax() / qf.amax();
    let top = (1..=24)
        .flat_map(|k| (0..n).map(move |i| (i, k)))
        .map(|(i, k)| free.harmonic(i, k).norm())
        .fold(0.0, f64::max);
    let dk = (1..=24)
        .flat_map(|k| (0..n).map(move |i| (i, k)))
        .map(|(i, k)| (free.harmonic(i, k) - soft.harmonic(i, k)).norm())
        .fold(0.0, f64::max)
        / top;
    eprintln!("static twist {d0:.1e}, harmonics >= 1 {dk:.1e}");
    assert!(d0 < 1e-6, "static twist {d0:.1e}");
    assert!(dk < 1e-6, "harmonics >= 1 {dk:.1e}");
    // The backlash is engaged and the mean mesh deflection carries the torque 20/r1.
    let u0 = 0.03 * qf[3] + 0.05 * qf[4];
    assert!(u0 > 1e-5, "{u0}");
}

/// The condensed formulation (receptances with `K0⁺` in the complement) equals the full one.
#[test]
fn condensed_equals_full_on_a_free_free_drivetrain() {
    let model = drivetrain(0.0, BALANCED);
    let basis = HarmonicBasis::new(300.0, 24).unwrap();
    let full =
        newton(&HarmonicBalance::with_formulation(&model, basis, Formulation::Full).unwrap());
    let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap();
    assert!(hb.is_condensed() && hb.rigid_modes().is_some());
    let cond = newton(&hb);
    let d = hbal::compare::relative_error(cond.harmonics(), full.harmonics(), 7, 24);
    eprintln!("condensed against full {d:.1e}");
    assert!(d < 1e-10, "condensed against full {d:.1e}");
}

/// Unbalanced mean torques: a clear error before solving, in both formulations.
#[test]
fn unbalanced_static_loads_are_an_error() {
    let model = drivetrain(0.0, -BALANCED);
    let basis = HarmonicBasis::new(300.0, 8).unwrap();
    for formulation in [Formulation::Full, Formulation::Condensed] {
        let err = HarmonicBalance::with_formulation(&model, basis, formulation).unwrap_err();
        let Error::UnbalancedStaticLoad { net, reference, .. } = &err else {
            panic!("{err}");
        };
        // 20 N m on the engine plus (-0.6)(-33.3) N m from the wheel, referred to the engine.
        assert!((net - 40.0).abs() < 1e-9, "{net}");
        assert_eq!(reference, "engine");
        let msg = err.to_string();
        assert!(msg.contains("the static loads do not balance"), "{msg}");
        assert!(msg.contains("`wheel`"), "{msg}");
    }
}

#[test]
fn cli_rejects_an_unbalanced_scene_with_exit_code_2() {
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/free_free_drivetrain.toml"
    );
    let text = std::fs::read_to_string(scene).unwrap();
    let marker = "road load torque";
    let line = text.lines().find(|l| l.contains(marker)).unwrap();
    let bad = text.replace(line, "  { dof = \"vehicle\", order = 0, cos = 1.0 },");
    let dir = std::env::temp_dir().join(format!("hbal-free-free-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("unbalanced.toml");
    std::fs::write(&path, bad).unwrap();
    for cmd in ["solve", "check"] {
        let out = common::hbal(&[cmd, path.to_str().unwrap()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd}: {stderr}");
        assert!(
            stderr.contains("the static loads do not balance"),
            "{stderr}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A singular `K0` whose null motion is restrained by an element without linear stiffness
/// (a pure cubic spring to ground) is not a rigid-body mode: the singular error stays.
#[test]
fn a_motion_held_only_by_a_nonlinear_element_is_not_free() {
    let model = Model::builder(&["a", "b"])
        .mass_diagonal(&[1.0, 1.0])
        .element(
            "shaft",
            &[("a", 1.0), ("b", -1.0)],
            LinearSpring::new(10.0, 0.1),
        )
        .element(
            "cubic",
            &[("a", 1.0)],
            hbal::force::CubicSpring::new(0.0, 5.0),
        )
        .load("a", 1, 1.0, 0.0)
        .build()
        .unwrap();
    for formulation in [Formulation::Full, Formulation::Condensed] {
        let basis = HarmonicBasis::new(3.0, 4).unwrap();
        let err = HarmonicBalance::with_formulation(&model, basis, formulation).unwrap_err();
        assert!(
            matches!(err, Error::SingularDynamicStiffness { harmonic: 0, .. }),
            "{formulation:?}: {err}"
        );
    }
}
