//! The exact condensation onto the element coordinates against the full formulation: the
//! same periodic solution to 1e-10 on the example scenes and on a torsional chain with two
//! gear meshes (mesh stiffness and backlash on one coordinate each), for Newton and for the
//! two-level Anderson map.

use hbal::compare::relative_error;
use hbal::force::{Backlash, MeshDamping, MeshProfile, MeshStiffness};
use hbal::nalgebra::DMatrix;
use hbal::scene::Scene;
use hbal::{Anderson, Formulation, HarmonicBalance, HarmonicBasis, Model, Newton, Solution};

pub(crate) fn solve(model: &Model, basis: HarmonicBasis, formulation: Formulation) -> Solution {
    let hb = HarmonicBalance::with_formulation(model, basis, formulation).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-13)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{formulation:?}: {}", sol.termination);
    sol
}

/// Every example scene with a nonlinear or time-varying element (H reduced to at most 32 or
/// the highest mesh order):
/// condensed and full agree to 1e-10.
#[test]
fn condensed_equals_full_on_the_example_scenes() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes");
    let mut checked = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let scene = Scene::load(&path).unwrap();
        // A linear line without elements has nothing to condense onto; a scene on several
        // base frequencies is condensed on the torus (tests/integration/torus_scene.rs).
        if scene.model.elements().is_empty() || scene.torus.is_some() {
            continue;
        }
        // At most 32 harmonics, but every mesh order kept.
        let orders = scene
            .model
            .elements()
            .iter()
            .filter_map(|e| e.law().time_order());
        let h = scene
            .basis
            .harmonics()
            .min(32.max(orders.max().unwrap_or(0)));
        // The car drivetrain's mesh at harmonic 851 is beyond the full formulation's dense
        // Newton (tests/integration/car_drivetrain.rs covers it).
        if scene.model.n_dofs() * (2 * h + 1) > hbal::solve::MAX_DENSE_UNKNOWNS {
            continue;
        }
        let basis = HarmonicBasis::new(scene.basis.omega(), h)
            .unwrap()
            .with_subharmonic(scene.basis.subharmonic())
            .unwrap();
        let full = solve(&scene.model, basis, Formulation::Full);
        // More element coordinates than DOFs (NLvib example 07: five elements on three
        // masses) cannot be condensed: a clear refusal, and `auto` picks the full formulation.
        if scene.model.elements().len() > scene.model.n_dofs() {
            let e = HarmonicBalance::with_formulation(&scene.model, basis, Formulation::Condensed)
                .unwrap_err()
                .to_string();
            assert!(e.contains("linearly dependent"), "{}: {e}", path.display());
            assert_eq!(Formulation::Auto.resolve(&scene.model), Formulation::Full);
            continue;
        }
        let cond = solve(&scene.model, basis, Formulation::Condensed);
        let n = scene.model.n_dofs();
        let d = relative_error(cond.harmonics(), full.harmonics(), n, h);
        assert!(
            d < 1e-10,
            "{}: condensed against full {d:.1e}",
            path.display()
        );
        assert_eq!(cond.dof_names(), full.dof_names());
        checked += 1;
    }
    assert!(checked >= 8, "{checked} scenes");
}

/// A 7-DOF chain: engine, flywheel, input shaft, gear 1 | gear 2, output, wheel; two meshes,
/// each a rectangular mesh stiffness and a backlash element on the same coordinate (so m = 2
/// coordinates for 3 elements), grounded by a soft spring, driven by a torque of order 1.
pub(crate) fn chain() -> Model {
    let names = ["engine", "flywheel", "shaft", "g1", "g2", "out", "wheel"];
    let inertia = [0.2, 0.5, 0.01, 0.002, 0.004, 0.02, 1.0];
    let n = names.len();
    let mut k = DMatrix::zeros(n, n);
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
    k[(6, 6)] += 50.0;
    k[(0, 0)] += 50.0;
    let d = &k * 2e-4;
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
            MeshStiffness::new(1, profile.clone(), MeshDamping::Constant(20.0)),
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
        .load("wheel", 0, -20.0 * r2 / r1, 0.0)
        .build()
        .unwrap()
}

#[test]
fn condensed_equals_full_on_a_two_mesh_chain() {
    let model = chain();
    let basis = HarmonicBasis::new(300.0, 24).unwrap();
    let full = solve(&model, basis, Formulation::Full);
    let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap();
    assert_eq!(hb.unknown_names(), ["u(mesh)", "u(clutch)"]);
    assert_eq!(hb.layout().n, 2);
    let cond = solve(&model, basis, Formulation::Condensed);
    let d = relative_error(cond.harmonics(), full.harmonics(), 7, 24);
    assert!(d < 1e-10, "condensed against full {d:.1e}");
    // The two-level Anderson map on the condensed problem, from a full-DOF warm start.
    let anderson = Anderson::new()
        .with_tolerance(1e-13)
        .unwrap()
        .with_coarse_harmonics(8);
    let a = anderson
        .solve_from(&hb, full.harmonics(), &mut hb.workspace())
        .unwrap();
    assert!(a.is_converged(), "{}", a.termination);
    let d = relative_error(a.harmonics(), full.harmonics(), 7, 24);
    assert!(d < 1e-10, "two-level condensed against full {d:.1e}");
}

/// A model without a nonlinear element has nothing to condense onto: a clear error.
#[test]
fn condensing_a_linear_model_is_an_error() {
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .stiffness(DMatrix::from_element(1, 1, 4.0))
        .load("x", 1, 1.0, 0.0)
        .build()
        .unwrap();
    let err = HarmonicBalance::with_formulation(
        &model,
        HarmonicBasis::new(1.3, 4).unwrap(),
        Formulation::Condensed,
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("no time-varying or nonlinear element"),
        "{err}"
    );
}

/// `∂R/∂Ω` of the condensed residual (the receptances' Ω-derivative from the same sparse
/// factors) against central differences of the residual (without the tail correction, whose
/// Ω-dependence `∂R/∂Ω` leaves out).
#[test]
fn condensed_omega_derivative_matches_finite_differences() {
    let model = chain();
    let omega = 300.0;
    let basis = HarmonicBasis::new(omega, 12)
        .unwrap()
        .with_tail_correction(false);
    let full = solve(&model, basis, Formulation::Full);
    let mut hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap();
    let mut ws = hb.workspace();
    let layout = hb.layout();
    // A point off the solution: the coordinates of the full solution, perturbed.
    let mut u = hb.unknowns_of(full.harmonics()).unwrap();
    for (i, v) in u.iter_mut().enumerate() {
        *v *= 1.0 + 0.1 * ((i % 5) as f64 - 2.0);
    }
    let mut x = vec![0.0; layout.len()];
    layout.pack(&u, &mut x);
    let mut analytic = vec![0.0; layout.len()];
    hb.omega_derivative_real_into(&x, &mut analytic, &mut ws)
        .unwrap();
    let step = 1e-5 * omega;
    let mut r = |o: f64| {
        hb.set_omega(o).unwrap();
        let mut out = vec![0.0; layout.len()];
        hb.residual_real_into(&x, &mut out, None, &mut ws).unwrap();
        out
    };
    let (rp, rm) = (r(omega + step), r(omega - step));
    let fd: Vec<f64> = rp
        .iter()
        .zip(&rm)
        .map(|(a, b)| (a - b) / (2.0 * step))
        .collect();
    let scale = fd.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let err = analytic
        .iter()
        .zip(&fd)
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(
        scale > 0.0 && err < 1e-6 * scale,
        "error {err:.2e} of {scale:.2e}"
    );
}

/// A split power path (input -> two countershafts -> output) closes a loop of meshes: the four
/// mesh coordinates are linearly dependent. `auto` then holds the problem in the full
/// formulation; an explicit `condensed` says why it cannot.
#[test]
fn auto_falls_back_to_full_on_dependent_mesh_coordinates() {
    let names = ["e1", "e2", "a", "b", "c", "d", "o1", "o2"];
    let mut builder = Model::builder(&names)
        .mass_diagonal(&[0.1, 0.05, 0.01, 0.01, 0.01, 0.01, 0.05, 0.2])
        .stiffness(DMatrix::from_fn(8, 8, |i, j| {
            // Shafts e1-e2-a and d-o1-o2, a soft ground spring on o2.
            let k = 1e4;
            let pairs = [(0, 1), (1, 2), (5, 6), (6, 7)];
            let mut v = 0.0;
            for &(p, q) in &pairs {
                if (i, j) == (p, q) || (i, j) == (q, p) {
                    v -= k;
                }
                if i == j && (i == p || i == q) {
                    v += k;
                }
            }
            if i == 7 && j == 7 {
                v += 1e3;
            }
            v
        }))
        .damping(DMatrix::from_diagonal_element(8, 8, 0.5))
        .load("e1", 1, 5.0, 0.0);
    let mesh = || {
        MeshStiffness::new(
            3,
            MeshProfile::Cosine {
                mean: 1e5,
                amplitude: 1e4,
            },
            MeshDamping::Constant(1.0),
        )
    };
    for (name, p, q) in [
        ("ab", "a", "b"),
        ("bd", "b", "d"),
        ("ac", "a", "c"),
        ("cd", "c", "d"),
    ] {
        builder = builder.element(name, &[(p, 1.0), (q, -1.0)], mesh());
    }
    let model = builder.build().unwrap();
    assert_eq!(Formulation::Auto.resolve(&model), Formulation::Condensed);
    let basis = HarmonicBasis::new(50.0, 8).unwrap();
    let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Auto).unwrap();
    assert_eq!(hb.formulation(), Formulation::Full);
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert!(sol.is_converged());
    let err = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap_err();
    assert!(err.to_string().contains("linearly dependent"), "{err}");
}

/// A singular `Z_1` at one Ω (undamped `K − Ω² M` with `Ω² = 1` an eigenvalue of
/// `K = [[2, −1], [−1, 2]]`, `M = I`) is an error, and the condensed balance moves on to
/// another Ω afterwards with the answer of one built there (it lost its condensation before).
#[test]
fn condensed_set_omega_recovers_after_a_singular_harmonic() {
    use hbal::force::CubicSpring;
    let model = Model::builder(&["a", "b"])
        .mass_diagonal(&[1.0, 1.0])
        .stiffness_triplets(&[(0, 0, 2.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 2.0)])
        .element("cubic", &[("a", 1.0)], CubicSpring::new(0.0, 0.1))
        .load("a", 1, 0.2, 0.0)
        .build()
        .unwrap();
    let basis = HarmonicBasis::new(0.7, 5).unwrap();
    let mut hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed).unwrap();
    assert!(hb.set_omega(1.0).is_err(), "Z_1 is singular at Ω = 1");
    hb.set_omega(1.5).unwrap();
    let moved = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    let fresh_hb = HarmonicBalance::with_formulation(
        &model,
        basis.with_omega(1.5).unwrap(),
        Formulation::Condensed,
    )
    .unwrap();
    let fresh = Newton::new()
        .solve(&fresh_hb, &mut fresh_hb.workspace())
        .unwrap();
    assert!(moved.is_converged() && fresh.is_converged());
    let d = relative_error(moved.harmonics(), fresh.harmonics(), 2, 5);
    assert!(d < 1e-12, "{d:e}");
}
