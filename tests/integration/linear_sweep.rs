//! Sweeps of linear time-invariant models: one solve per harmonic per point, multipliers from
//! the state matrix's eigenvalues, an error estimate of rounding only (issue 31, item 3).

use hbal::continuation::{BranchStop, Continuation};
use hbal::force::LinearSpring;
use hbal::{HarmonicBasis, Model};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Masses 1, 2, 0.5; springs 100 (ground), 80, 50 as elements and structure; Rayleigh damping
/// `D = a M + b K`; loads on orders 1 and 2.
const A: f64 = 0.05;
const B: f64 = 2e-4;

fn chain() -> (Model, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 2.0, 0.5]));
    let k = DMatrix::from_row_slice(
        3,
        3,
        &[180.0, -80.0, 0.0, -80.0, 130.0, -50.0, 0.0, -50.0, 50.0],
    );
    let d = &m * A + &k * B;
    // The spring between the last two masses as an element (folded into K0 and D0).
    let mut k_structure = k.clone();
    let mut d_structure = d.clone();
    for (i, j, s) in [(1, 1, 1.0), (2, 2, 1.0), (1, 2, -1.0), (2, 1, -1.0)] {
        k_structure[(i, j)] -= s * 50.0;
        d_structure[(i, j)] -= s * 50.0 * B;
    }
    let model = Model::builder(&["a", "b", "c"])
        .mass(m.clone())
        .stiffness(k_structure)
        .damping(d_structure)
        .element(
            "spring",
            &[("b", 1.0), ("c", -1.0)],
            LinearSpring::new(50.0, 50.0 * B),
        )
        .load("a", 1, 1.0, 0.0)
        .load("c", 2, 0.0, 0.4)
        .build()
        .unwrap();
    (model, m, d, k)
}

/// `Z_k⁻¹ F_k` in closed form per harmonic.
fn closed_form(
    m: &DMatrix<f64>,
    d: &DMatrix<f64>,
    k: &DMatrix<f64>,
    omega: f64,
    h: usize,
) -> Vec<Complex64> {
    let mut q = Vec::new();
    for order in 0..=h {
        let w = order as f64 * omega;
        let z = DMatrix::from_fn(3, 3, |i, j| {
            Complex64::new(k[(i, j)] - w * w * m[(i, j)], w * d[(i, j)])
        });
        let mut f = nalgebra::DVector::<Complex64>::zeros(3);
        if order == 1 {
            f[0] = Complex64::new(1.0, 0.0);
        }
        if order == 2 {
            f[2] = Complex64::new(0.0, -0.4);
        }
        q.extend(z.lu().solve(&f).unwrap().iter().copied());
    }
    q
}

#[test]
fn a_linear_run_up_is_the_closed_form_at_every_point_and_resolves_its_peaks() {
    let (model, m, d, k) = chain();
    let (from, to, h) = (0.01, 30.0, 4);
    let branch = Continuation {
        error_estimate: true,
        ..Continuation::default()
    }
    .run(&model, HarmonicBasis::new(from, h).unwrap(), to, |_| {})
    .unwrap();
    assert_eq!(branch.stop, BranchStop::Reached);
    assert!(
        branch.start.contains("linear time-invariant"),
        "{}",
        branch.start
    );
    let last = branch.points.last().unwrap();
    assert_eq!(last.omega, to);
    assert!(branch.points.len() < 600, "{} points", branch.points.len());
    for p in &branch.points {
        let exact = closed_form(&m, &d, &k, p.omega, h);
        let scale = exact.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for (a, b) in p.harmonics.iter().zip(&exact) {
            assert!((a - b).norm() <= 1e-12 * scale, "{a} vs {b} at {}", p.omega);
        }
        let e = p.error_estimate.unwrap();
        assert!(e < 1e-11, "error estimate {e} at {}", p.omega);
        assert!(p.stable() == Some(true));
    }
    // Every resonance of the first harmonic of mass a is caught to 1 % of its peak: the
    // closed form's maximum on a fine grid against the branch's largest point nearby.
    let amplitude = |w: f64| closed_form(&m, &d, &k, w, 1)[3].norm();
    let sym = m.clone().cholesky().unwrap();
    let l_inv = sym.l().try_inverse().unwrap();
    let eig = (&l_inv * &k * l_inv.transpose()).symmetric_eigen();
    for wn in eig.eigenvalues.iter().map(|l| l.sqrt()) {
        let grid = (0..20001).map(|i| wn * (0.9 + 0.2 * i as f64 / 20000.0));
        let peak = grid.map(amplitude).fold(0.0, f64::max);
        let found = branch
            .points
            .iter()
            .filter(|p| (p.omega / wn - 1.0).abs() < 0.1)
            .map(|p| p.harmonics[3].norm())
            .fold(0.0, f64::max);
        assert!(found > 0.99 * peak, "mode at {wn}: {found} vs peak {peak}");
    }
}

/// With Rayleigh damping the modes decouple: `λ = -ζω ± iω√(1-ζ²)` with `2ζω = a + bω²`, so
/// each pair of multipliers has the modulus `exp(-(a + bω²) T / 2)`; their product is
/// `exp(tr(A) T) = exp(-tr(M⁻¹D) T)` (Liouville).
#[test]
fn multipliers_are_the_modal_exponentials() {
    let (model, m, d, k) = chain();
    let omega = 7.3;
    let branch = Continuation::default()
        .run(&model, HarmonicBasis::new(omega, 4).unwrap(), 7.4, |_| {})
        .unwrap();
    let f = branch.points[0].floquet.as_ref().unwrap();
    assert_eq!(f.multipliers.len(), 6);
    assert_eq!(f.neutral, 0);
    let t = std::f64::consts::TAU / omega;
    let l_inv = m.clone().cholesky().unwrap().l().try_inverse().unwrap();
    let eig = (&l_inv * &k * l_inv.transpose()).symmetric_eigen();
    let mut want: Vec<f64> = eig
        .eigenvalues
        .iter()
        .flat_map(|w2| [(-(A + B * w2) * t / 2.0).exp(); 2])
        .collect();
    want.sort_by(|a, b| b.total_cmp(a));
    for (mu, w) in f.multipliers.iter().zip(&want) {
        assert!((mu.norm() / w - 1.0).abs() < 1e-10, "{} vs {w}", mu.norm());
    }
    let trace: f64 = (m.clone().try_inverse().unwrap() * d).trace();
    let product: f64 = f.multipliers.iter().map(|m| m.norm()).product();
    assert!((product / (-trace * t).exp() - 1.0).abs() < 1e-10);
}

/// A free-free chain: the rigid-body mode's double multiplier 1 is neutral, the rest decide.
#[test]
fn a_free_free_linear_model_leaves_its_rigid_mode_out() {
    let model = Model::builder(&["a", "b", "c"])
        .mass_diagonal(&[1.0, 2.0, 0.5])
        .element(
            "s1",
            &[("a", 1.0), ("b", -1.0)],
            LinearSpring::new(80.0, 0.1),
        )
        .element(
            "s2",
            &[("b", 1.0), ("c", -1.0)],
            LinearSpring::new(50.0, 0.05),
        )
        .load("a", 1, 1.0, 0.0)
        .load("c", 1, -0.5, 0.0)
        .build()
        .unwrap();
    let branch = Continuation::default()
        .run(&model, HarmonicBasis::new(2.0, 3).unwrap(), 20.0, |_| {})
        .unwrap();
    assert_eq!(branch.stop, BranchStop::Reached);
    for p in &branch.points {
        let f = p.floquet.as_ref().unwrap();
        assert_eq!((f.neutral, f.multipliers.len()), (2, 4));
        assert!(f.is_stable() && f.max_abs() < 1.0);
    }
}

fn hbal() -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"));
    c.current_dir(env!("CARGO_MANIFEST_DIR"));
    c
}

/// The command line: a run-up of the 10-inertia line from 0.1 rpm reaches `--to` (it stopped
/// at the 2000-point limit before, its stability failing at the first point), and says why its
/// error estimate is rounding.
#[test]
fn the_cli_run_up_of_a_linear_line_reaches_its_end() {
    let out = hbal()
        .args([
            "sweep",
            "tests/data/linear/shaft_line_10.toml",
            "--from",
            "0.1",
            "--to",
            "6000",
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["reached"], true);
    let points = v["points"].as_array().unwrap();
    assert!(points.len() < 2000, "{} points", points.len());
    assert!(points.iter().all(|p| p["stable"] == true));
    let worst = points
        .iter()
        .map(|p| p["error_estimate"].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(worst < 1e-9, "{worst}");
    let text = hbal()
        .args([
            "sweep",
            "tests/data/linear/shaft_line_10.toml",
            "--from",
            "1000",
            "--to",
            "2000",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&text.stdout);
    assert!(
        stdout.contains("linear time-invariant model is exact in H"),
        "{stdout}"
    );
}

/// The exact piecewise method's sweep of a linear time-invariant model: the same closed form,
/// by one solve per harmonic (it integrated the state matrix's exponentials at every point:
/// the 10-inertia line's 1000 points took 1.3 s, now 0.07 s).
#[test]
fn an_exact_method_sweep_of_a_linear_model_is_one_solve_per_harmonic() {
    let (model, m, d, k) = chain();
    let cont = Continuation {
        method: hbal::solve::Method::PiecewiseExact(Default::default()),
        ..Continuation::default()
    };
    let values: Vec<f64> = (0..50).map(|i| 0.5 + 0.4 * i as f64).collect();
    let branch = hbal::continuation::sweep_values(
        &values,
        |w| Ok((&model, HarmonicBasis::new(w, 4)?)),
        &cont,
        |_| {},
    )
    .unwrap();
    assert_eq!(branch.stop, BranchStop::Reached);
    assert_eq!(branch.points.len(), 50);
    assert!(
        branch.start.contains("linear time-invariant"),
        "{}",
        branch.start
    );
    for p in &branch.points {
        let exact = closed_form(&m, &d, &k, p.omega, 4);
        let scale = exact.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for (a, b) in p.harmonics.iter().zip(&exact) {
            assert!((a - b).norm() <= 1e-12 * scale, "{a} vs {b} at {}", p.omega);
        }
        assert!(p.error_estimate.unwrap() < 1e-12);
        assert_eq!(p.stable(), Some(true));
    }
}

/// A lightly damped resonance narrower than a step, on a DOF that hardly counts in the norm
/// (found in review: the sweep stepped over it, max |b| 0.0014 for a peak of 0.5): every
/// resonance of a loaded order gets points at its peak and half-power speeds.
#[test]
fn a_narrow_resonance_is_not_stepped_over() {
    let out = hbal()
        .args([
            "sweep",
            "tests/data/linear/narrow_peak.toml",
            "--from",
            "20",
            "--to",
            "400",
            "--no-stability",
            "--json",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let peak = v["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["max_abs"][1].as_f64().unwrap())
        .fold(0.0, f64::max);
    // b: k = 1e4, c = 0.02, unit force: the peak is 1/(c ω_d) = 0.5 at 100 rad/s.
    assert!((peak / 0.5 - 1.0).abs() < 1e-3, "{peak}");
}

/// A parameter sweep of a linear model changes the model at every value: its multipliers
/// follow (found in review: the first value's eigenvalues were reused), `e^{-c T / 2m}`.
#[test]
fn a_parameter_sweep_of_a_linear_model_takes_each_models_multipliers() {
    let make = |c: f64| {
        Model::builder(&["x"])
            .mass_diagonal(&[1.0])
            .stiffness(DMatrix::from_element(1, 1, 1e4))
            .damping(DMatrix::from_element(1, 1, c))
            .load("x", 1, 1.0, 0.0)
            .build()
    };
    let values = [1.0, 50.0, 100.0];
    let branch = hbal::continuation::sweep_values(
        &values,
        |c| Ok((make(c)?, HarmonicBasis::new(50.0, 2)?)),
        &Continuation::default(),
        |_| {},
    )
    .unwrap();
    let t = std::f64::consts::TAU / 50.0;
    for (p, c) in branch.points.iter().zip(values) {
        let got = p.floquet.as_ref().unwrap().max_abs();
        let want = (-c * t / 2.0).exp();
        assert!((got / want - 1.0).abs() < 1e-10, "c = {c}: {got} vs {want}");
    }
}

/// The exact method's sweep of a linear model with a load above H (which harmonic balance
/// refuses) still runs, by the exact method (found in review).
#[test]
fn an_exact_sweep_with_a_load_above_h_falls_back_to_the_exact_method() {
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .stiffness(DMatrix::from_element(1, 1, 100.0))
        .damping(DMatrix::from_element(1, 1, 0.5))
        .load("x", 3, 1.0, 0.0)
        .build()
        .unwrap();
    let cont = Continuation {
        method: hbal::solve::Method::PiecewiseExact(Default::default()),
        ..Continuation::default()
    };
    let branch = hbal::continuation::sweep_values(
        &[2.0, 3.0, 4.0],
        |w| Ok((&model, HarmonicBasis::new(w, 2)?)),
        &cont,
        |_| {},
    )
    .unwrap();
    assert_eq!(branch.stop, BranchStop::Reached);
    assert_eq!(branch.points.len(), 3);
}
