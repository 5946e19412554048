//! The `hbal` binary on every example scene: `solve`, `check` and `compare`, their JSON and
//! their exit codes.

use crate::common::cli::scenes_dir;
use crate::common::hbal;

#[test]
fn every_example_scene_solves_and_checks() {
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            continue; // a scene's own files, e.g. chain_mtx/
        }
        let p = path.to_str().unwrap();
        let out = hbal(&["check", p]);
        assert!(
            out.status.success(),
            "check {p}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        if hbal::scene::Scene::load(&path).unwrap().torus.is_some() {
            continue; // on several base frequencies: tests/integration/torus_cli.rs
        }
        let out = hbal(&["solve", p, "--json"]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "solve {p}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
        assert_eq!(doc["converged"], true, "{p}");
        for key in [
            "termination",
            "method",
            "iterations",
            "residual",
            "fundamental_rad_s",
            "harmonics",
            "samples",
            "solve_seconds",
            "dofs",
            "history",
        ] {
            assert!(doc.get(key).is_some(), "{p}: missing {key}");
        }
        let dof = &doc["dofs"][0];
        assert!(dof["name"].is_string() && dof["max_abs"].as_f64().unwrap() > 0.0);
        assert_eq!(dof["harmonics"][0]["order"], 0);
        assert!(doc["solve_seconds"].as_f64().unwrap() >= 0.0);
        count += 1;
    }
    assert!(count >= 7, "{count} scenes");
}

#[test]
fn solve_json_matches_the_library_and_writes_outputs() {
    let scene = scenes_dir().join("two_shaft_6000rpm.toml");
    let dir = std::env::temp_dir().join(format!("hbal-cli-{}", std::process::id()));
    let out = hbal(&[
        "solve",
        scene.to_str().unwrap(),
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // q(t) = Σ cos_k cos(kΩt) + sin_k sin(kΩt): the static part is L0 / K_mean, shifted by the
    // mesh variation (reference: 2.98961e-5).
    let a0 = doc["dofs"][0]["harmonics"][0]["cos"].as_f64().unwrap();
    assert!((a0 - 2.98961e-5).abs() < 2e-9, "{a0}");
    let omega = doc["fundamental_rad_s"].as_f64().unwrap();
    assert!((omega - 4.0 * 6000.0 * std::f64::consts::TAU / 60.0).abs() < 1e-9);
    for f in [
        "harmonics.csv",
        "time_series.csv",
        "time_series.svg",
        "spectrum.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let csv = std::fs::read_to_string(dir.join("harmonics.csv")).unwrap();
    assert!(csv.starts_with("dof,harmonic,shaft_order,cos,sin\ngear,0,0,"));
    // Overrides.
    let out = hbal(&[
        "solve",
        scene.to_str().unwrap(),
        "--json",
        "--method",
        "anderson",
        "--harmonics",
        "16",
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["method"], "anderson");
    assert_eq!(doc["harmonics"], 16);
}

#[test]
fn non_converged_solve_exits_1_with_its_result() {
    let scene = scenes_dir().join("gear_backlash.toml");
    let out = hbal(&[
        "solve",
        scene.to_str().unwrap(),
        "--json",
        "--method",
        "fixed_point",
        "--no-fallback",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["converged"], false);
    assert_eq!(doc["termination"], "maximum iterations reached");
}

#[test]
fn compare_reports_every_method() {
    let scene = scenes_dir().join("duffing.toml");
    let out = hbal(&["compare", scene.to_str().unwrap(), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let methods = doc["methods"].as_array().unwrap();
    assert_eq!(methods.len(), 4);
    for m in methods {
        assert_eq!(m["converged"], true, "{m}");
        assert!(m["error_vs_time_domain"].as_f64().unwrap() < 1e-6, "{m}");
        // Per quantity against the time domain's samples: the Duffing spring's coordinate
        // and force, each against its own range (H = 7: 5e-12 estimated, agreeing here).
        let q = &m["worst_quantity_vs_time_domain"];
        assert!(q["error"].as_f64().unwrap() < 1e-6, "{m}");
        assert!(q["range"].as_f64().unwrap() > 0.1, "{m}");
        assert!(q["name"].as_str().unwrap().contains("spring"), "{m}");
    }
}

/// A free-free model's `hbal compare`: the whole-solution error without the rigid-body mean
/// angle (a convention; `compare::model_relative_error`'s doc test shifts it), and the worst
/// quantity by its dynamic part against the time domain's samples (3.4e-2: the mesh force's
/// peaks at H = 128).
#[test]
fn compare_of_a_free_free_model_ignores_the_rigid_mean_angle() {
    let scene = scenes_dir().join("free_free_drivetrain.toml");
    let out = hbal(&[
        "compare",
        scene.to_str().unwrap(),
        "--json",
        "--method",
        "newton",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let m = &doc["methods"][0];
    assert!(m["error_vs_time_domain"].as_f64().unwrap() < 1e-5, "{m}");
    assert!(
        m["worst_quantity_vs_time_domain"]["error"]
            .as_f64()
            .unwrap()
            < 0.1,
        "{m}"
    );
}
