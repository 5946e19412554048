//! Free lines held only by damping to ground (issue 33): a propeller damper or dampers at the
//! crank throws on a line without a spring to ground, and modal damping whose rigid-mode
//! rounding is not zero. Harmonic 0 is solved in the complement of the motion damping holds
//! (`K0 r = 0`, `w_e·r = 0`, `D r ≠ 0`), with the mean angle `rᵀ M q_0 = 0`; harmonics `k ≥ 1`
//! as usual; stability counts one neutral multiplier (the position) and keeps the decaying
//! velocity. Checked against the closed form (static twists, the complex solve of each
//! harmonic, the state matrix's eigenvalues), in both formulations and by shooting.

use crate::common;

use hbal::force::{CubicSpring, LinearSpring};
use hbal::harmonic::from_cos_sin;
use hbal::nalgebra::{DMatrix, DVector};
use hbal::num_complex::Complex64;
use hbal::stability::FloquetOptions;
use hbal::{Error, FixedPoint, Formulation, HarmonicBalance, HarmonicBasis, Model, Newton};

const J: [f64; 3] = [0.1, 0.2, 0.4];
const K: [[f64; 3]; 3] = [[1e4, -1e4, 0.0], [-1e4, 3e4, -2e4], [0.0, -2e4, 2e4]];
/// Damping in the shafts and a damper to ground of 4 N m s/rad on `c` (a propeller).
const D: [[f64; 3]; 3] = [[2.0, -2.0, 0.0], [-2.0, 5.0, -3.0], [0.0, -3.0, 7.0]];
const T: f64 = 50.0;
const OMEGA: f64 = 120.0;

fn matrix(a: &[[f64; 3]; 3]) -> DMatrix<f64> {
    DMatrix::from_fn(3, 3, |r, c| a[r][c])
}

/// The line with the drive `T` on `a`, the load `-T` on `c`, a first-order torque on `a`, a
/// second-order one on `c`, and `extra` elements.
fn line(d: DMatrix<f64>, cubic: Option<f64>) -> Model {
    let mut b = Model::builder(&["a", "b", "c"])
        .mass_diagonal(&J)
        .stiffness(matrix(&K))
        .damping(d)
        .load("a", 0, T, 0.0)
        .load("c", 0, -T, 0.0)
        .load("a", 1, 5.0, 2.0)
        .load("c", 2, 0.0, 1.5);
    if let Some(k3) = cubic {
        b = b.element(
            "soft",
            &[("a", 1.0), ("b", -1.0)],
            CubicSpring::new(0.0, k3),
        );
    }
    b.build().unwrap()
}

fn newton(hb: &HarmonicBalance) -> hbal::Solution {
    let sol = Newton::new()
        .with_tolerance(1e-13)
        .unwrap()
        .solve(hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    sol
}

/// Harmonic 0: the twists `T/k1`, `T/k2` and the mean angle `Σ J_i q_i = 0`; harmonics 1 and
/// 2: the 3×3 complex solves `Z_k Q_k = F_k` with the damper to ground in `D`.
fn assert_closed_form(sol: &hbal::Solution, d: &DMatrix<f64>) {
    let q0: Vec<f64> = (0..3).map(|i| sol.harmonic(i, 0).re).collect();
    assert!((q0[0] - q0[1] - T / 1e4).abs() < 1e-12 * T / 1e4, "{q0:?}");
    assert!((q0[1] - q0[2] - T / 2e4).abs() < 1e-12 * T / 1e4, "{q0:?}");
    let mean: f64 = (0..3).map(|i| J[i] * q0[i]).sum();
    assert!(mean.abs() < 1e-14 * T / 1e4, "mean angle {mean:e}");
    let loads = [
        (1, [from_cos_sin(5.0, 2.0), 0.0.into(), 0.0.into()]),
        (2, [0.0.into(), 0.0.into(), from_cos_sin(0.0, 1.5)]),
    ];
    for (k, f) in loads {
        let w = k as f64 * OMEGA;
        let z = DMatrix::from_fn(3, 3, |r, c| {
            let m = if r == c { J[r] } else { 0.0 };
            Complex64::new(K[r][c] - w * w * m, w * d[(r, c)])
        });
        let q = z.lu().solve(&DVector::from_row_slice(&f)).unwrap();
        for i in 0..3 {
            let e = (sol.harmonic(i, k) - q[i]).norm();
            assert!(e < 1e-11 * q.camax(), "harmonic {k}, dof {i}: {e:e}");
        }
    }
}

#[test]
fn a_line_damped_to_ground_equals_the_closed_form() {
    // A cubic spring of zero stiffness: an element for the condensed formulation to keep.
    let model = line(matrix(&D), Some(0.0));
    let basis = HarmonicBasis::new(OMEGA, 3).unwrap();
    for formulation in [Formulation::Full, Formulation::Condensed] {
        let hb = HarmonicBalance::with_formulation(&model, basis, formulation).unwrap();
        let rigid = hb.rigid_modes().expect("the motion damping holds");
        assert_eq!((rigid.len(), rigid.free(), rigid.held()), (1, 0, 1));
        assert_closed_form(&newton(&hb), &matrix(&D));
        let fixed = FixedPoint::new().solve(&hb, &mut hb.workspace()).unwrap();
        assert!(fixed.is_converged(), "{}", fixed.termination);
        assert_closed_form(&fixed, &matrix(&D));
    }
}

/// The multipliers `e^{λT}` of the state matrix `[[0, I], [-M⁻¹K, -M⁻¹D]]` without its one
/// zero eigenvalue (the position the damper leaves free).
fn state_multipliers(d: &DMatrix<f64>) -> Vec<Complex64> {
    let mut a = DMatrix::<f64>::zeros(6, 6);
    for i in 0..3 {
        a[(i, 3 + i)] = 1.0;
        for j in 0..3 {
            a[(3 + i, j)] = -K[i][j] / J[i];
            a[(3 + i, 3 + j)] = -d[(i, j)] / J[i];
        }
    }
    let mut lambdas: Vec<Complex64> = a.complex_eigenvalues().iter().copied().collect();
    lambdas.sort_by(|x, y| x.norm().total_cmp(&y.norm()));
    assert!(lambdas[0].norm() < 1e-9, "{lambdas:?}");
    let period = std::f64::consts::TAU / OMEGA;
    lambdas[1..].iter().map(|l| (l * period).exp()).collect()
}

/// The largest distance from a multiplier of `expected` to the nearest of `got`.
fn distance(expected: &[Complex64], got: &[Complex64]) -> f64 {
    assert_eq!(expected.len(), got.len(), "{got:?}");
    expected
        .iter()
        .map(|e| {
            got.iter()
                .map(|g| (e - g).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// One neutral multiplier, five that decide: the closed form for the linear line, and the
/// same by shooting where a negligible cubic spring makes the line nonlinear.
#[test]
fn the_damped_line_has_one_neutral_multiplier_and_the_state_matrix_multipliers() {
    let expected = state_multipliers(&matrix(&D));
    // The rigid velocity decays: e^{-4 T / ΣJ} is among them.
    let rigid = (-4.0 / 0.7 * std::f64::consts::TAU / OMEGA).exp();
    assert!(
        expected.iter().any(|m| (m.norm() - rigid).abs() < 1e-3),
        "{expected:?}"
    );
    for (cubic, tolerance) in [(None, 1e-10), (Some(1e-6), 1e-6)] {
        let model = line(matrix(&D), cubic);
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(OMEGA, 8).unwrap()).unwrap();
        let sol = newton(&hb);
        let f = FloquetOptions::default().compute(&model, &sol).unwrap();
        assert_eq!(f.neutral, 1, "{cubic:?}");
        let d = distance(&expected, &f.multipliers);
        assert!(d < tolerance, "{cubic:?}: {d:e} {:?}", f.multipliers);
        assert!(f.is_stable());
    }
}

/// Modal damping as shaft-line tools build it, `D = M Φ diag(2ζω_i) Φᵀ M` from the
/// eigen-decomposition of `(K, M)`, with `ω_i = √|λ_i|` also for the rigid mode, whose `λ` is
/// rounding: `D r` is small but not zero. Accepted, and the closed form holds with that `D`.
#[test]
fn modal_damping_from_an_eigen_decomposition_is_accepted() {
    let m_half = DMatrix::from_diagonal(&DVector::from_iterator(3, J.iter().map(|j| j.sqrt())));
    let m_inv_half = m_half.clone().try_inverse().unwrap();
    let eig = (&m_inv_half * matrix(&K) * &m_inv_half).symmetric_eigen();
    let phi = &m_inv_half * &eig.eigenvectors; // mass-normalised modes
    let zeta = 0.02;
    let diag = DMatrix::from_diagonal(&eig.eigenvalues.map(|l| 2.0 * zeta * l.abs().sqrt()));
    let m = DMatrix::from_diagonal(&DVector::from_row_slice(&J));
    let d = &m * &phi * diag * phi.transpose() * &m;
    let d = (&d + d.transpose()) * 0.5;
    let ones = DVector::from_element(3, 1.0);
    let leak = (&d * &ones).amax() / d.amax();
    eprintln!("modal damping on the rigid mode: |D r| / |D| = {leak:.1e}");
    let model = line(d.clone(), None);
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(OMEGA, 3).unwrap()).unwrap();
    assert_eq!(hb.rigid_modes().map(|r| r.len()), Some(1));
    assert_closed_form(&newton(&hb), &d);
}

/// A mean torque on the motion damping holds: a clear error, in the library and as exit 2.
#[test]
fn a_static_load_on_a_motion_held_by_damping_is_refused() {
    let model = Model::builder(&["a", "b", "c"])
        .mass_diagonal(&J)
        .stiffness(matrix(&K))
        .damping(matrix(&D))
        .load("a", 0, T, 0.0)
        .build()
        .unwrap();
    let err = HarmonicBalance::new(&model, HarmonicBasis::new(OMEGA, 3).unwrap()).unwrap_err();
    let Error::UnbalancedStaticLoad { net, .. } = &err else {
        panic!("{err}");
    };
    assert!((net.abs() - T).abs() < 1e-9, "{net}");
    let scene = "dofs = [\"a\", \"b\", \"c\"]\nmass = [[0.1, 0, 0], [0, 0.2, 0], [0, 0, 0.4]]\n\
        stiffness = [[1e4, -1e4, 0], [-1e4, 3e4, -2e4], [0, -2e4, 2e4]]\n\
        damping = [[2, -2, 0], [-2, 5, -3], [0, -3, 7]]\n\
        fundamental = { rad_s = 120.0 }\nharmonics = { count = 3 }\n\
        loads = [{ dof = \"a\", order = 0, cos = 50.0 }]\n";
    let dir = common::cli::temp_dir("damped-ground");
    let path = dir.join("unbalanced.toml");
    std::fs::write(&path, scene).unwrap();
    let out = common::hbal(&["solve", path.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("net torque 5.0"), "{stderr}");
    // Balanced, the same line solves (exit 0).
    std::fs::write(
        &path,
        scene.replace(
            "cos = 50.0 }",
            "cos = 50.0 }, { dof = \"c\", order = 0, cos = -50.0 }",
        ),
    )
    .unwrap();
    let out = common::hbal(&["solve", path.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The exact piecewise method separates free bodies only: a motion damping holds is refused
/// with the reason (harmonic balance solves it, above).
#[test]
fn the_exact_method_refuses_a_motion_held_by_damping() {
    let model = line(matrix(&D), None);
    let basis = HarmonicBasis::new(OMEGA, 3).unwrap();
    let Err(err) = hbal::solve::PiecewiseExact::new().solve_exact(&model, &basis) else {
        panic!("the exact method accepted a motion held by damping");
    };
    assert!(
        err.to_string().contains("held only by damping to ground"),
        "{err}"
    );
    // A spring, not a damper, on `c`: no such motion, and the model is not free either.
    let grounded = Model::builder(&["a", "b"])
        .mass_diagonal(&[1.0, 1.0])
        .element("s", &[("a", 1.0), ("b", -1.0)], LinearSpring::new(1e3, 1.0))
        .element("g", &[("b", 1.0)], LinearSpring::new(1e2, 0.0))
        .load("a", 1, 1.0, 0.0)
        .build()
        .unwrap();
    assert!(hbal::solve::PiecewiseExact::new()
        .solve_exact(&grounded, &basis)
        .is_ok());
}

/// `hbal modes` of a linear line needs no operating point: the modes of the damped line with
/// an unbalanced mean torque (which `solve` refuses) are the generalised eigenvalues of
/// `(K, M)`, one rigid.
#[test]
fn modes_of_a_linear_line_need_no_operating_point() {
    let scene = "dofs = [\"a\", \"b\", \"c\"]\nmass = [[0.1, 0, 0], [0, 0.2, 0], [0, 0, 0.4]]\n\
        stiffness = [[1e4, -1e4, 0], [-1e4, 3e4, -2e4], [0, -2e4, 2e4]]\n\
        damping = [[2, -2, 0], [-2, 5, -3], [0, -3, 7]]\n\
        fundamental = { rad_s = 120.0 }\nharmonics = { count = 3 }\n\
        loads = [{ dof = \"a\", order = 0, cos = 50.0 }, { dof = \"a\", order = 1, cos = 5.0 }]\n";
    let dir = common::cli::temp_dir("damped-modes");
    let path = dir.join("line.toml");
    std::fs::write(&path, scene).unwrap();
    let out = common::hbal(&["modes", "--json", path.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = common::cli::json_of(&out);
    assert_eq!(doc["linear"], true);
    assert_eq!(doc["rigid_modes"], 1);
    let m_inv_half =
        DMatrix::from_diagonal(&DVector::from_iterator(3, J.iter().map(|j| 1.0 / j.sqrt())));
    let mut expected: Vec<f64> = (&m_inv_half * matrix(&K) * &m_inv_half)
        .symmetric_eigenvalues()
        .iter()
        .map(|l| l.max(0.0).sqrt() / std::f64::consts::TAU)
        .collect();
    expected.sort_by(f64::total_cmp);
    let got: Vec<f64> = doc["modes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["mean_hz"].as_f64().unwrap())
        .collect();
    assert_eq!(got.len(), 3, "{doc}");
    assert!(got[0].abs() < 1e-6, "{got:?}");
    for (g, e) in got.iter().zip(&expected).skip(1) {
        assert!((g - e).abs() < 1e-10 * e, "{got:?} vs {expected:?}");
    }
    let text = common::hbal(&["modes", path.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&text.stdout);
    assert!(
        stdout.contains("a linear model (no operating point needed)"),
        "{stdout}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two separate lines, each held only by its own propeller damper, the mean torque on line a
/// only: each line's balance is judged against the whole mean load, so line b (net torque
/// rounding, ~1e-17) is not refused (it was, found by review), and stability counts two
/// neutral multipliers.
#[test]
fn two_lines_each_held_by_a_damper_balance_separately() {
    let model = Model::builder(&["a1", "a2", "b1", "b2"])
        .mass_diagonal(&[1.0, 2.0, 1.0, 1.5])
        .stiffness(DMatrix::from_row_slice(
            4,
            4,
            &[
                1.0, -1.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, -2.0, 0.0, 0.0, -2.0, 2.0,
            ],
        ))
        .damping(DMatrix::from_row_slice(
            4,
            4,
            &[
                0.03, -0.03, 0.0, 0.0, -0.03, 0.23, 0.0, 0.0, 0.0, 0.0, 0.04, -0.04, 0.0, 0.0,
                -0.04, 0.34,
            ],
        ))
        .load("a1", 0, 0.05, 0.0)
        .load("a2", 0, -0.05, 0.0)
        .load("a1", 1, 0.1, 0.0)
        .load("b1", 1, 0.2, 0.0)
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.0, 5).unwrap()).unwrap();
    assert_eq!(hb.rigid_modes().map(|r| (r.len(), r.held())), Some((2, 2)));
    let sol = newton(&hb);
    // Line a's twist is the mean torque over its shaft.
    let twist = sol.harmonic(0, 0).re - sol.harmonic(1, 0).re;
    assert!((twist - 0.05).abs() < 1e-12, "{twist}");
    let f = FloquetOptions::default().compute(&model, &sol).unwrap();
    assert_eq!(f.neutral, 2);
    // An unbalanced mean torque on line b is still refused.
    let unbalanced = Model::builder(&["a1", "a2", "b1", "b2"])
        .mass_diagonal(&[1.0, 2.0, 1.0, 1.5])
        .stiffness(model.dense("test").unwrap().stiffness)
        .damping(model.dense("test").unwrap().damping)
        .load("a1", 0, 0.05, 0.0)
        .load("a2", 0, -0.05, 0.0)
        .load("b1", 0, 1e-3, 0.0)
        .build()
        .unwrap();
    let err = HarmonicBalance::new(&unbalanced, HarmonicBasis::new(1.0, 5).unwrap()).unwrap_err();
    assert!(matches!(err, Error::UnbalancedStaticLoad { .. }), "{err}");
}
