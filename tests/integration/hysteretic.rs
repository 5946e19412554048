//! Hysteretic damping (a loss factor, `c = H/ω`): the closed form of one DOF, the condensed
//! formulation equal to the full one on a nonlinear model, the analyses without a time-domain
//! form refused with the reason, bad input named.

use hbal::force::CubicSpring;
use hbal::linear::Formulation;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
use nalgebra::DMatrix;

/// Two DOFs, a cubic spring on `a`, H = η K on the chain.
fn model() -> Model {
    let k = DMatrix::from_row_slice(2, 2, &[5.0, -2.0, -2.0, 3.0]);
    Model::builder(&["a", "b"])
        .mass(DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.5]))
        .damping(DMatrix::from_row_slice(2, 2, &[0.01, 0.0, 0.0, 0.01]))
        .hysteretic(&k * 0.04)
        .stiffness(k)
        .element("duffing", &[("a", 1.0)], CubicSpring::new(0.0, 1.5))
        .load("b", 1, 0.3, 0.1)
        .load("a", 0, 0.2, 0.0)
        .build()
        .unwrap()
}

/// `m ẍ + k x` with a loss factor η under `F cos ωt`: `|X| = F / |k − mω² + i η k|` at every
/// ω, and no static part (a static load sees `k` alone).
#[test]
fn one_dof_has_the_closed_form_at_every_frequency() {
    let (m, k, eta) = (2.0, 50.0, 0.05);
    let model = Model::builder(&["x"])
        .mass_diagonal(&[m])
        .stiffness(DMatrix::from_element(1, 1, k))
        .hysteretic(DMatrix::from_element(1, 1, eta * k))
        .load("x", 0, 3.0, 0.0)
        .load("x", 2, 1.0, 0.0)
        .build()
        .unwrap();
    for w in [0.5, 2.0, 2.5, 4.0] {
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(w, 3).unwrap()).unwrap();
        let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
        let q = sol.harmonics();
        let want = 1.0 / num_complex::Complex64::new(k - m * (2.0 * w) * (2.0 * w), eta * k);
        assert!(
            (q[2] - want).norm() < 1e-13 * want.norm(),
            "ω {w}: {} vs {want}",
            q[2]
        );
        assert!((q[0].re - 3.0 / k).abs() < 1e-15, "static {}", q[0]);
    }
}

#[test]
fn condensed_equals_full_with_hysteretic_damping() {
    let model = model();
    let solve = |f: Formulation| {
        let hb = HarmonicBalance::with_formulation(&model, HarmonicBasis::new(1.3, 9).unwrap(), f)
            .unwrap();
        let sol = Newton::new()
            .with_tolerance(1e-13)
            .unwrap()
            .solve(&hb, &mut hb.workspace())
            .unwrap();
        assert!(sol.is_converged());
        sol.harmonics().to_vec()
    };
    let (full, condensed) = (solve(Formulation::Full), solve(Formulation::Condensed));
    let scale = full.iter().map(|v| v.norm()).fold(0.0, f64::max);
    for (a, b) in full.iter().zip(&condensed) {
        assert!((a - b).norm() < 1e-11 * scale, "{a} vs {b}");
    }
    // No time-domain form: the Floquet analysis and the time integration refuse.
    let err = hbal::stability::FloquetOptions::default()
        .compute(&model, &{
            let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.3, 9).unwrap()).unwrap();
            Newton::new().solve(&hb, &mut hb.workspace()).unwrap()
        })
        .unwrap_err();
    assert!(err.to_string().contains("no time-domain form"), "{err}");
    let err = hbal::timesim::TimeSimulation::new()
        .run(&model, 1.3)
        .unwrap_err();
    assert!(err.to_string().contains("hysteretic damping"), "{err}");
}

const SCENE: &str = r#"
fundamental = { rpm = 600 }
harmonics = { count = 4 }
loads = [{ dof = "a", order = 1, cos = 100.0 }]
[line]
loss_factor = 0.02
disks = [{ name = "a", inertia = 0.5, damping = 0.2 }, { name = "b", inertia = 1.0 }]
shafts = [{ from = "a", to = "b", stiffness = 1e4 }]
"#;

/// Solve reports the stability as not available; compare and piecewise_exact refuse (exit 2);
/// bad loss factors and a `[line]` beside `hysteretic_damping` are named.
#[test]
fn front_ends_say_what_hysteretic_damping_rules_out() {
    let dir = crate::common::cli::temp_dir("hysteretic");
    let write = |name: &str, text: &str| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_string_lossy().into_owned()
    };
    let good = write("good.toml", SCENE);
    let out = crate::common::hbal(&["solve", &good]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        text.contains("not available with hysteretic damping"),
        "{text}"
    );
    for args in [
        vec!["compare", &good],
        vec!["solve", &good, "--method", "piecewise_exact"],
    ] {
        let out = crate::common::hbal(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("no time-domain form"), "{args:?}: {err}");
    }
    for (text, path, words) in [
        (
            SCENE.replace("loss_factor = 0.02", "loss_factor = -0.02"),
            "line.loss_factor",
            ">= 0",
        ),
        (
            SCENE.replace("stiffness = 1e4 }", "stiffness = 1e4, loss_factor = inf }"),
            "line.shafts[0].loss_factor",
            "finite",
        ),
        (
            SCENE.replace(
                "[line]",
                "hysteretic_damping = [[1.0, 0.0], [0.0, 1.0]]\n[line]",
            ),
            "line",
            "`hysteretic_damping`",
        ),
    ] {
        crate::common::cli::check_refuses(&dir, &text, path, words);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `hysteretic_damping` written as a matrix equals the line's `loss_factor` (η k per shaft).
#[test]
fn a_loss_factor_is_the_hysteretic_matrix_written_by_hand() {
    let line = hbal::scene::Scene::from_str(SCENE, "line.toml").unwrap();
    let hand = hbal::scene::Scene::from_str(
        "fundamental = { rpm = 600 }\nharmonics = { count = 4 }\n\
         loads = [{ dof = \"a\", order = 1, cos = 100.0 }]\ndofs = [\"a\", \"b\"]\n\
         mass = [[0.5, 0], [0, 1.0]]\nstiffness = [[1e4, -1e4], [-1e4, 1e4]]\n\
         damping = [[0.2, 0], [0, 0]]\nhysteretic_damping = [[200.0, -200.0], [-200.0, 200.0]]\n",
        "hand.toml",
    )
    .unwrap();
    assert_eq!(
        line.model.hysteretic().to_dense(),
        hand.model.hysteretic().to_dense()
    );
    assert!(line.model.has_hysteretic_damping());
}

/// A scene written back (`write_scene`) keeps its hysteretic damping: the same H, the same
/// solution.
#[test]
fn written_scenes_keep_the_hysteretic_damping() {
    use hbal::scene::export::{write_scene, SceneSettings};
    let scene = hbal::scene::Scene::from_str(SCENE, "line.toml").unwrap();
    let dir = crate::common::cli::temp_dir("hysteretic-export");
    let file = dir.join("line.toml");
    write_scene(
        &scene.model,
        &SceneSettings::new("line", "rpm", 600.0, 4),
        &file,
    )
    .unwrap();
    let back = hbal::scene::Scene::load(&file).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        back.model.hysteretic().to_dense(),
        scene.model.hysteretic().to_dense()
    );
    let solve = |s: &hbal::scene::Scene| {
        let hb = HarmonicBalance::new(&s.model, s.basis).unwrap();
        Newton::new()
            .solve(&hb, &mut hb.workspace())
            .unwrap()
            .harmonics()
            .to_vec()
    };
    assert_eq!(solve(&scene), solve(&back));
}
