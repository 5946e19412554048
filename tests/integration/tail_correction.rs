//! The tail correction on a model with two meshes that jump at different places of the period
//! and share a DOF: the mobility `C = Wᵀ M⁻¹ W` has cross terms, both formulations must give
//! the same answer, and the correction must bring both meshes' harmonics to the time domain's.

use hbal::compare::relative_error;
use hbal::force::{MeshDamping, MeshProfile, MeshStiffness};
use hbal::timesim::TimeSimulation;
use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Model, Newton};

/// Three inertias on a grounded shaft, two gear meshes (a–b: one cycle per period, contact
/// ratio 1.6; b–c: two cycles, contact ratio 1.35, phase 0.7), static and alternating loads.
/// Natural frequencies up to about 4e4 rad/s, far below H = 32 harmonics of 3000 rad/s.
fn model() -> Model {
    let mesh = |teeth, ratio, two, phase| {
        MeshStiffness::new(
            teeth,
            MeshProfile::Rectangular {
                one_tooth: 0.5 * two,
                two_tooth: two,
                contact_ratio: ratio,
            },
            MeshDamping::Proportional(2e-6),
        )
        .with_phase(phase)
    };
    Model::builder(&["a", "b", "c"])
        .mass_diagonal(&[1e-3, 2e-3, 1.5e-3])
        .stiffness_triplets(&[(0, 0, 1e5), (2, 2, 2e5)])
        .damping_triplets(&[(0, 0, 1.0), (2, 2, 1.0)])
        .element("ab", &[("a", 1.0), ("b", -1.0)], mesh(1, 1.6, 5e5, 0.0))
        .element("bc", &[("b", 1.0), ("c", -1.0)], mesh(2, 1.35, 8e5, 0.7))
        .load("a", 0, 10.0, 0.0)
        .load("a", 1, 2.0, 0.5)
        .load("c", 2, 0.0, 1.0)
        .build()
        .unwrap()
}

const OMEGA: f64 = 3000.0;

fn solve(
    model: &Model,
    h: usize,
    tail: bool,
    formulation: Formulation,
) -> (Vec<hbal::num_complex::Complex64>, bool) {
    let basis = HarmonicBasis::new(OMEGA, h)
        .unwrap()
        .with_tail_correction(tail);
    let hb = HarmonicBalance::with_formulation(model, basis, formulation).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-12)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}", sol.termination);
    (sol.harmonics().to_vec(), hb.tail_corrected())
}

/// Against the time domain (rtol 1e-12, restarted at every jump), harmonics 0..=32 of all
/// three DOFs: the truncation is good to O(H⁻³), the correction far better; the full and
/// condensed formulations agree to 1e-10 with it.
#[test]
fn two_meshes_sharing_a_dof() {
    let model = model();
    let td = TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        ..TimeSimulation::default()
    }
    .run(&model, OMEGA)
    .unwrap();
    assert!(td.converged);
    let mut plain = Vec::new();
    let mut corrected = Vec::new();
    for h in [32, 64] {
        let (q, applied) = solve(&model, h, true, Formulation::Full);
        assert!(applied, "H = {h}: the correction should apply");
        corrected.push(relative_error(&q, &td.harmonics, 3, 32));
        let (q, _) = solve(&model, h, false, Formulation::Full);
        plain.push(relative_error(&q, &td.harmonics, 3, 32));
        let (c, _) = solve(&model, h, true, Formulation::Condensed);
        let (f, _) = solve(&model, h, true, Formulation::Full);
        let d = relative_error(&c, &f, 3, h);
        assert!(d < 1e-10, "H = {h}: condensed against full {d:e}");
    }
    eprintln!("plain {plain:?}, corrected {corrected:?}");
    for (p, c) in plain.iter().zip(&corrected) {
        assert!(c * 30.0 < *p, "plain {plain:?}, corrected {corrected:?}");
    }
    assert!(corrected[1] < 1e-7, "{corrected:?}");
}

/// The default: off at a fixed H (the plain truncation, with a note where the correction
/// would apply), on for automatic harmonics; `tail_correction = true` turns it on at a fixed
/// H, `false` off also for automatic harmonics. The two-shaft model at 6000 rpm, H = 32.
#[test]
fn off_at_a_fixed_h_on_for_automatic_harmonics() {
    use crate::piecewise_exact::{run, scene};
    let with = std::fs::read_to_string(scene("two_shaft_6000rpm.toml")).unwrap();
    assert!(with.contains("\ntail_correction = true\n"));
    let dir = std::env::temp_dir().join(format!("hbal-tail-default-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = |name: &str, text: String| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    let default = file(
        "default.toml",
        with.replace("\ntail_correction = true\n", "\n"),
    );
    let off = file(
        "off.toml",
        with.replace("tail_correction = true", "tail_correction = false"),
    );
    let kept = |args: &[&str]| {
        let (code, out, err) = run(args);
        assert_eq!(code, Some(0), "{err}");
        let json: serde_json::Value = serde_json::from_str(&out).unwrap();
        (
            json["error_estimate"]["kept_harmonics"].as_f64().unwrap(),
            err,
        )
    };
    let fixed = ["--json", "--no-stability"];
    // Fixed H: the plain truncation (2.1e-4 estimated), and a note on the correction.
    let (plain, err) = kept(&[&["solve", &default][..], &fixed].concat());
    assert!((1e-4..5e-4).contains(&plain), "{plain:e}");
    assert!(err.contains("`tail_correction = true`"), "{err}");
    // Turned on: about 1e-6, no note on it.
    let (on, err) = kept(&[&["solve", &scene("two_shaft_6000rpm.toml")][..], &fixed].concat());
    assert!(on < 3e-6 && plain / on > 100.0, "{on:e}");
    assert!(!err.contains("`tail_correction = true`"), "{err}");
    // --harmonics N keeps the scene's setting: on at H = 64, far below the plain 64's error.
    let (at64, err) = kept(
        &[
            &[
                "solve",
                &scene("two_shaft_6000rpm.toml"),
                "--harmonics",
                "64",
            ][..],
            &fixed,
        ]
        .concat(),
    );
    let (plain64, _) = kept(&[&["solve", &default, "--harmonics", "64"][..], &fixed].concat());
    assert!(at64 < plain64 / 100.0, "{at64:e} {plain64:e}");
    assert!(!err.contains("`tail_correction = true`"), "{err}");
    // Turned off explicitly: no note on it either.
    let (_, err) = kept(&[&["solve", &off][..], &fixed].concat());
    assert!(!err.contains("`tail_correction = true`"), "{err}");
    // Automatic harmonics on the harmonics 0..H: H = 32 with the correction by default.
    let auto = ["--harmonics", "auto:harmonics", "--json", "--no-stability"];
    let (code, out, err) = run(&[&["solve", &default][..], &auto].concat());
    assert_eq!(code, Some(0), "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["harmonics"], 32, "{}", json["harmonics"]);
    // ... and without it where the scene turns it off: a higher H.
    let (code, out, err) = run(&[&["solve", &off][..], &auto].concat());
    assert_eq!(code, Some(0), "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(
        json["harmonics"].as_u64().unwrap() >= 128,
        "{}",
        json["harmonics"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}
