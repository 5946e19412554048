//! `hbal solve` and `hbal sweep` with Floquet stability, start files (round trip, mismatches)
//! and solver overrides.

use crate::common::cli::{backlash_at_08, json_of, scenes_dir, temp_dir};
use crate::common::hbal;
use std::path::Path;

#[test]
fn solve_reports_floquet_stability() {
    let scene = scenes_dir().join("gear_backlash.toml");
    let p = scene.to_str().unwrap();
    let out = hbal(&["solve", p, "--json"]);
    assert_eq!(out.status.code(), Some(0));
    let doc = json_of(&out);
    assert!(doc["truncation_estimate"].as_f64().unwrap() >= 0.0);
    let st = &doc["stability"];
    assert_eq!(st["stable"], true, "{st}");
    // The stable orbit at W = 0.7: |μ| = exp(-0.05·2π/0.7) for both multipliers.
    let expected = (-0.05 * std::f64::consts::TAU / 0.7).exp();
    assert!((expected - 0.638394).abs() < 1e-6);
    assert!(
        (st["max_abs"].as_f64().unwrap() - expected).abs() < 1e-6,
        "{st}"
    );
    let moduli = st["moduli"].as_array().unwrap();
    let mult = st["multipliers"].as_array().unwrap();
    assert_eq!(moduli.len(), 2);
    assert_eq!(mult.len(), 2);
    for (m, r) in mult.iter().zip(moduli) {
        let (re, im) = (m[0].as_f64().unwrap(), m[1].as_f64().unwrap());
        assert!((re.hypot(im) - expected).abs() < 1e-6, "{m}");
        assert!((r.as_f64().unwrap() - expected).abs() < 1e-6, "{r}");
    }
    assert_eq!(st["neutral"], 0);
    assert_eq!(st["polished"], true);
    assert!(st["orbit_correction"].as_f64().unwrap() < 1e-4, "{st}");
    // Text: one stability line, no warning.
    let out = hbal(&["solve", p]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(
            "  stability: stable, max |μ| = 0.638394 (2 multipliers, 0 neutral), orbit correction"
        ),
        "{text}"
    );
    assert!(!String::from_utf8_lossy(&out.stderr).contains("warning"));
    // --no-stability.
    let out = hbal(&["solve", p, "--json", "--no-stability"]);
    assert_eq!(json_of(&out)["stability"], serde_json::Value::Null);
    let out = hbal(&["solve", p, "--no-stability"]);
    assert!(!String::from_utf8_lossy(&out.stdout).contains("stability"));
    // The unstable middle orbit at W = 0.8 (multipliers 2.11 and 0.216): a warning on stderr.
    let dir = temp_dir("unstable");
    let w08 = backlash_at_08(&dir);
    let out = hbal(&["solve", w08.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0));
    let st = json_of(&out)["stability"].clone();
    assert_eq!(st["stable"], false, "{st}");
    assert!(
        (st["max_abs"].as_f64().unwrap() - 2.1103).abs() < 1e-3,
        "{st}"
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning: the converged orbit is unstable (max |μ| = 2.11"),
        "{err}"
    );
    let out = hbal(&["solve", w08.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("  stability: unstable, max |μ| = 2.11"));
    // An unconverged solve has no orbit to judge.
    let out = hbal(&[
        "solve",
        p,
        "--json",
        "--method",
        "fixed_point",
        "--no-fallback",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(json_of(&out)["stability"], serde_json::Value::Null);
}

#[test]
fn solve_start_file_round_trip() {
    let dir = temp_dir("start");
    let scene = scenes_dir().join("two_shaft_gear_pair.toml");
    let p = scene.to_str().unwrap();
    let out = hbal(&["solve", p, "--json", "--no-stability"]);
    assert_eq!(out.status.code(), Some(0));
    let first = json_of(&out);
    let file = dir.join("gear_pair.json");
    std::fs::write(&file, &out.stdout).unwrap();
    for method in ["newton", "broyden", "anderson"] {
        let out = hbal(&[
            "solve",
            p,
            "--json",
            "--no-stability",
            "--method",
            method,
            "--start",
            file.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(0), "{method}");
        let doc = json_of(&out);
        assert_eq!(doc["converged"], true);
        assert!(
            doc["iterations"].as_u64().unwrap() <= 1,
            "{method}: {}",
            doc["iterations"]
        );
        assert_eq!(doc["start"], file.to_str().unwrap());
        let (a, b) = (
            &first["dofs"][1]["harmonics"][1],
            &doc["dofs"][1]["harmonics"][1],
        );
        let (a, b) = (a["cos"].as_f64().unwrap(), b["cos"].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-9 * a.abs(), "{a} vs {b}");
    }
    let out = hbal(&["solve", p, "--start", file.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("from --start"));
    // A different H: the file's harmonics are truncated (or padded) to the scene's.
    let out = hbal(&[
        "solve",
        p,
        "--json",
        "--harmonics",
        "32",
        "--start",
        file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(json_of(&out)["harmonics"], 32);
    // Fewer harmonics than the mesh order (20 teeth) is refused, naming the element.
    let out = hbal(&["solve", p, "--harmonics", "8"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("element `mesh` varies at order 20"));
    // The start picks the orbit: the backlash pair at W = 0.8 started on the stable orbit of
    // W = 0.7 stays on the stable lower orbit, not the unstable middle one.
    let gb = dir.join("gb07.json");
    let out = hbal(&[
        "solve",
        scenes_dir().join("gear_backlash.toml").to_str().unwrap(),
        "--json",
    ]);
    std::fs::write(&gb, &out.stdout).unwrap();
    let w08 = backlash_at_08(&dir);
    let out = hbal(&[
        "solve",
        w08.to_str().unwrap(),
        "--json",
        "--start",
        gb.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let doc = json_of(&out);
    assert_eq!(doc["stability"]["stable"], true, "{}", doc["stability"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("was computed at 0.7 rad/s"));
}

#[test]
fn mismatched_start_file_is_bad_input() {
    let dir = temp_dir("badstart");
    let duffing = scenes_dir().join("duffing.toml");
    let pair = scenes_dir().join("two_shaft_gear_pair.toml");
    let out = hbal(&["solve", pair.to_str().unwrap(), "--json", "--no-stability"]);
    let good: serde_json::Value = json_of(&out);
    let mut one_dof = good.clone();
    one_dof["dofs"].as_array_mut().unwrap().pop();
    let mut no_harmonics = good.clone();
    no_harmonics["dofs"][0]["harmonics"] = serde_json::json!([]);
    let mut bad_number = good.clone();
    bad_number["dofs"][0]["harmonics"][1]["cos"] = serde_json::json!("x");
    let cases: Vec<(&str, String, &Path, &str)> = vec![
        (
            "not_json.json",
            "dofs = 1".into(),
            &pair,
            "not a JSON object",
        ),
        (
            "other_scene.json",
            good.to_string(),
            &duffing,
            "DOF `pinion` is not in the scene",
        ),
        (
            "missing_dof.json",
            one_dof.to_string(),
            &pair,
            "no harmonics for DOF(s) gear",
        ),
        (
            "no_harmonics.json",
            no_harmonics.to_string(),
            &pair,
            "has no `harmonics`",
        ),
        (
            "bad_number.json",
            bad_number.to_string(),
            &pair,
            "dofs[0].harmonics[1]: `cos` must be a finite number",
        ),
        (
            "no_dofs.json",
            "{\"converged\": true}".into(),
            &pair,
            "no `dofs` list",
        ),
    ];
    for (name, text, scene, expected) in cases {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        for cmd in [
            vec![
                "solve",
                scene.to_str().unwrap(),
                "--start",
                file.to_str().unwrap(),
            ],
            vec![
                "sweep",
                scene.to_str().unwrap(),
                "--to",
                "1e4",
                "--start",
                file.to_str().unwrap(),
            ],
        ] {
            let out = hbal(&cmd);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{name} {cmd:?}: {err}");
            assert!(err.contains(expected), "{name}: `{err}` lacks `{expected}`");
            assert!(
                err.contains(name),
                "{name}: the message must name the file: {err}"
            );
            assert!(!err.contains("panicked"), "{err}");
        }
    }
    let out = hbal(&[
        "solve",
        pair.to_str().unwrap(),
        "--start",
        "/nonexistent/start.json",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/start.json: cannot read"));
}

#[test]
fn solver_overrides_on_solve_compare_and_sweep() {
    let scene = scenes_dir().join("gear_backlash.toml");
    let p = scene.to_str().unwrap();
    let out = hbal(&[
        "solve",
        p,
        "--json",
        "--samples",
        "96",
        "--tolerance",
        "1e-8",
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(json_of(&out)["samples"], 96);
    for args in [
        vec!["solve", p, "--samples", "40"],
        vec!["sweep", p, "--to", "0.8", "--samples", "40"],
        vec!["compare", p, "--samples", "40"],
    ] {
        let out = hbal(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--samples") && err.contains("need N >= 2H+1 = 65"),
            "{err}"
        );
    }
    let out = hbal(&["solve", p, "--tolerance", "2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--tolerance"));
    // compare: one method, overridden basis.
    let out = hbal(&[
        "compare",
        p,
        "--json",
        "--method",
        "broyden",
        "--harmonics",
        "16",
        "--samples",
        "64",
        "--tolerance",
        "1e-9",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = json_of(&out);
    let methods = doc["methods"].as_array().unwrap();
    assert_eq!(methods.len(), 1);
    assert_eq!(methods[0]["method"], "broyden");
    assert!(methods[0]["residual"].as_f64().unwrap() <= 1e-9);
    // sweep: H, N, no stability, a point limit.
    let out = hbal(&[
        "sweep",
        p,
        "--from",
        "0.4",
        "--to",
        "1.6",
        "--json",
        "--harmonics",
        "16",
        "--samples",
        "64",
        "--no-stability",
        "--max-points",
        "5",
    ]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "the point limit stops the branch"
    );
    let doc = json_of(&out);
    assert_eq!(doc["reached"], false);
    assert!(
        doc["stop"].as_str().unwrap().contains("point limit"),
        "{}",
        doc["stop"]
    );
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 5);
    for pt in points {
        assert_eq!(pt["harmonics"][0].as_array().unwrap().len(), 17);
        assert_eq!(pt["stable"], serde_json::Value::Null);
        assert_eq!(pt["multipliers_abs"], serde_json::Value::Null);
    }
    let out = hbal(&[
        "sweep",
        p,
        "--from",
        "0.7",
        "--to",
        "0.75",
        "--json",
        "--method",
        "broyden",
        "--tolerance",
        "1e-9",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = json_of(&out);
    assert!(doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .all(|p| p["residual"].as_f64().unwrap() <= 1e-9));
    let out = hbal(&["sweep", p, "--to", "0.8", "--max-points", "0"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn sweep_starts_from_a_start_file() {
    let dir = temp_dir("sweepstart");
    let scene = scenes_dir().join("gear_backlash.toml");
    // The stable lower orbit at W = 0.8 (from the W = 0.7 orbit), as a start file.
    let out = hbal(&["solve", scene.to_str().unwrap(), "--json"]);
    let w07 = dir.join("w07.json");
    std::fs::write(&w07, &out.stdout).unwrap();
    let w08 = backlash_at_08(&dir);
    let out = hbal(&[
        "solve",
        w08.to_str().unwrap(),
        "--json",
        "--start",
        w07.to_str().unwrap(),
    ]);
    let lower = dir.join("lower08.json");
    std::fs::write(&lower, &out.stdout).unwrap();
    let sweep = |start: Option<&Path>| {
        let mut args = vec!["sweep", scene.to_str().unwrap(), "--to", "0.82", "--json"];
        if let Some(s) = start {
            args.extend(["--start", s.to_str().unwrap()]);
        } else {
            args.extend(["--from", "0.8"]);
        }
        let out = hbal(&args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        json_of(&out)
    };
    // --from defaults to the start file's speed; the branch is the stable lower one.
    let doc = sweep(Some(&lower));
    assert_eq!(doc["from"], 0.8);
    let points = doc["points"].as_array().unwrap();
    assert!((points[0]["speed"].as_f64().unwrap() - 0.8).abs() < 1e-12);
    assert!(points.iter().all(|p| p["stable"] == true), "{points:?}");
    // Without it, the linear start finds the unstable middle orbit.
    let doc = sweep(None);
    assert_eq!(doc["points"][0]["stable"], false);
}
