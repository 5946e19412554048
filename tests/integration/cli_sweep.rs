//! `hbal sweep` over speed and over a scene field: folds, interpolated fold positions, every
//! example scene around its speed, points kept before an invalid value.

use crate::common::cli::{json_of, scenes_dir, temp_dir};
use crate::common::hbal;

#[test]
fn sweep_follows_the_backlash_branch_through_its_folds() {
    let scene = scenes_dir().join("gear_backlash.toml");
    let dir = std::env::temp_dir().join(format!("hbal-sweep-{}", std::process::id()));
    let out = hbal(&[
        "sweep",
        scene.to_str().unwrap(),
        "--from",
        "0.4",
        "--to",
        "1.6",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["reached"], true);
    assert!(doc["folds"].as_u64().unwrap() >= 2);
    let points = doc["points"].as_array().unwrap();
    assert!(
        points.iter().any(|p| p["stable"] == false),
        "the middle branch is unstable"
    );
    assert!(points.iter().any(|p| p["bifurcation"] == "Fold"));
    // Every point names its worst quantity (the contact's coordinate or the gear's angle, the
    // same signal here) with an error against its range (7.6e-6 at most, at H = 32).
    for p in points {
        let q = &p["worst_quantity"];
        assert!(q["error"].as_f64().unwrap() < 1e-3, "{p}");
        assert!(q["range"].as_f64().unwrap() > 0.0, "{p}");
    }
    let csv = std::fs::read_to_string(dir.join("branch.csv")).unwrap();
    assert!(csv
        .starts_with("rad_s,stable,fold,bifurcation,max_abs_x,amp_x_k0_order_0,amp_x_k1_order_1"));
    assert!(csv.lines().next().unwrap().ends_with(
        ",multipliers_abs,residual,truncation,fold_speed,spurious_turn,bifurcation_speed,error_estimate,error_estimate_harmonics"
    ));
    assert!(dir.join("frequency_response_x.svg").exists());
    let out = hbal(&["sweep", scene.to_str().unwrap(), "--from=-1", "--to", "1.6"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--from must be a finite speed > 0"));
}

#[test]
fn parameter_sweep_over_a_scene_field() {
    let scene = scenes_dir().join("duffing.toml");
    let out = hbal(&[
        "sweep",
        scene.to_str().unwrap(),
        "--parameter",
        "elements[0].alpha",
        "--from",
        "0",
        "--to",
        "1",
        "--points",
        "11",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = doc["points"].as_array().unwrap();
    assert_eq!(points.len(), 11);
    assert_eq!(points[10]["parameter"], 1.0);
    assert!(
        points.iter().all(|p| p["stable"].is_boolean()),
        "stability by default"
    );
    // α = 1 is the scene itself: the same amplitude as a plain solve.
    let solve = hbal(&["solve", scene.to_str().unwrap(), "--json"]);
    let doc2: serde_json::Value = serde_json::from_slice(&solve.stdout).unwrap();
    let a = points[10]["max_abs"][0].as_f64().unwrap();
    let b = doc2["dofs"][0]["max_abs"].as_f64().unwrap();
    assert!((a - b).abs() < 1e-9 * b, "{a} vs {b}");
    // A jump (fold in the load amplitude) stops the sweep with exit 1 and a reason.
    let out = hbal(&[
        "sweep",
        scene.to_str().unwrap(),
        "--parameter",
        "loads[0].cos",
        "--from",
        "0.01",
        "--to",
        "0.3",
        "--points",
        "30",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(doc["stop"]
        .as_str()
        .unwrap()
        .contains("no convergence at parameter"));
    let out = hbal(&[
        "sweep",
        scene.to_str().unwrap(),
        "--parameter",
        "elements[0].alfa",
        "--from",
        "0",
        "--to",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no field `alfa`"));
}

#[test]
fn parameter_sweep_keeps_points_before_an_invalid_value() {
    let scene = scenes_dir().join("gear_backlash.toml");
    let dir = std::env::temp_dir().join(format!("hbal-psweep-{}", std::process::id()));
    // The half backlash goes negative half way: the scene is invalid there.
    let out = hbal(&[
        "sweep",
        scene.to_str().unwrap(),
        "--parameter",
        "elements[0].half_backlash",
        "--from",
        "1.0",
        "--to=-0.6",
        "--points",
        "9",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(out.status.code(), Some(1), "{doc}");
    assert!(doc["points"].as_array().unwrap().len() >= 4, "{doc}");
    assert!(
        doc["stop"].as_str().unwrap().contains("half_backlash"),
        "{doc}"
    );
    assert!(dir.join("branch.csv").exists());
    // Case-insensitive JSON extension, and --harmonics keeps the scene's N when it can.
    let upper = dir.join("SCENE.JSON");
    std::fs::copy(scenes_dir().join("duffing_resonance.json"), &upper).unwrap();
    assert!(hbal(&["check", upper.to_str().unwrap()]).status.success());
    let out = hbal(&[
        "solve",
        scenes_dir()
            .join("two_shaft_6000rpm.toml")
            .to_str()
            .unwrap(),
        "--harmonics",
        "16",
        "--json",
    ]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        doc["samples"], 256,
        "the scene's default N for H = 32 carries H = 16 as well"
    );
}

/// Every example scene sweeps 5 % up and 5 % down from its own speed, with stability, exit 0
/// and finite multipliers everywhere.
#[test]
fn every_example_scene_sweeps_around_its_speed() {
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            continue; // a scene's own files, e.g. chain_mtx/
        }
        let p = path.to_str().unwrap();
        let scene = hbal::scene::Scene::load(&path).unwrap();
        if scene.torus.is_some() {
            continue; // on several base frequencies: tests/integration/torus_cli.rs
        }
        let speed = scene.basis.omega() / scene.omega_per_speed;
        for to in [1.05 * speed, 0.95 * speed] {
            let to_arg = format!("{to}");
            let out = hbal(&["sweep", p, "--to", &to_arg, "--json"]);
            assert_eq!(
                out.status.code(),
                Some(0),
                "{p} to {to}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            let doc = json_of(&out);
            assert_eq!(doc["reached"], true, "{p}");
            let points = doc["points"].as_array().unwrap();
            assert!(points.len() >= 2, "{p}");
            let first = points[0]["speed"].as_f64().unwrap();
            assert!(
                (first - speed).abs() <= 1e-9 * speed,
                "{p}: starts at {first}"
            );
            let last = points.last().unwrap()["speed"].as_f64().unwrap();
            assert!(
                (last - to).abs() <= 1e-6 * to,
                "{p}: ends at {last}, not {to}"
            );
            // Hysteretic damping: the stability is not available, and said so.
            if scene.model.has_hysteretic_damping() {
                assert!(points.iter().all(|pt| pt["stable"].is_null()), "{p}");
                continue;
            }
            // Laws with memory: multipliers by shooting on the time-domain model.
            if scene.model.memory_element().is_some() {
                assert!(
                    points
                        .iter()
                        .all(|pt| pt["stable"].is_boolean() && pt["multipliers_abs"].is_array()),
                    "{p}"
                );
                continue;
            }
            for pt in points {
                let abs = pt["multipliers_abs"]
                    .as_array()
                    .unwrap_or_else(|| panic!("{p}: {pt}"));
                assert!(
                    abs.iter().all(|m| m.as_f64().is_some_and(f64::is_finite)),
                    "{p}: {pt}"
                );
                assert!(pt["stable"].is_boolean(), "{p}");
                assert!(pt["multipliers"].as_array().unwrap().len() == abs.len());
                assert!(
                    pt["neutral"].is_u64() && pt["orbit_correction"].is_f64(),
                    "{p}"
                );
                assert!(
                    pt["residual"].as_f64().unwrap() < 1e-8,
                    "{p}: {}",
                    pt["residual"]
                );
                assert!(pt["truncation"].as_f64().unwrap().is_finite(), "{p}");
            }
        }
        count += 1;
    }
    assert!(count >= 9, "{count} scenes");
}

/// The Duffing curve from 1.2 down to 1.14 runs round both folds; they are reported at their
/// interpolated positions (extended-system values 2.2115438 and 1.1701620) in text, JSON and
/// CSV.
#[test]
fn sweep_reports_interpolated_folds() {
    let scene = scenes_dir().join("duffing.toml");
    let p = scene.to_str().unwrap();
    let dir = temp_dir("folds");
    let out = hbal(&[
        "sweep",
        p,
        "--to",
        "1.14",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = json_of(&out);
    let mut folds: Vec<f64> = doc["fold_speeds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    folds.sort_by(f64::total_cmp);
    assert_eq!(folds.len(), 2, "{folds:?}");
    assert!((folds[0] - 1.1701620).abs() < 1e-5, "{folds:?}");
    assert!((folds[1] - 2.2115438).abs() < 1e-5, "{folds:?}");
    assert_eq!(doc["folds"], 2);
    let with_fold: Vec<_> = doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["fold"] == true)
        .collect();
    assert_eq!(with_fold.len(), 2);
    assert!(with_fold.iter().all(|p| p["fold_speed"].is_f64()));
    assert!(doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["fold"] == false)
        .all(|p| p["fold_speed"].is_null()));
    let text = String::from_utf8_lossy(&hbal(&["sweep", p, "--to", "1.14"]).stdout).to_string();
    assert!(text.contains("fold at 1.17016"), "{text}");
    assert!(text.contains("fold at 2.21154"), "{text}");
    assert!(text.contains("rad_s (interpolated)"), "{text}");
    let csv = std::fs::read_to_string(dir.join("branch.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    let (fold, fold_speed, residual, truncation) = (
        col("fold"),
        col("fold_speed"),
        col("residual"),
        col("truncation"),
    );
    col("spurious_turn");
    let mut csv_folds = Vec::new();
    for line in csv.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len());
        assert!(cells[residual].parse::<f64>().unwrap() < 1e-8);
        assert!(cells[truncation].parse::<f64>().is_ok());
        if cells[fold] == "true" {
            csv_folds.push(cells[fold_speed].parse::<f64>().unwrap());
        } else {
            assert_eq!(cells[fold_speed], "");
        }
    }
    csv_folds.sort_by(f64::total_cmp);
    assert!((csv_folds[0] - folds[0]).abs() < 1e-9 && (csv_folds[1] - folds[1]).abs() < 1e-9);
}

/// A `--parameter` sweep of the speed itself solves each point at that point's Ω: the two-shaft
/// model's max |q| at 5000 and 7000 rpm equals `hbal solve` of the scene at those speeds (a
/// sweep that kept the first value's Ω, or the scene's, would be 0.4 % off at 5000 or 7000 rpm).
#[test]
fn a_parameter_sweep_of_the_speed_solves_at_each_speed() {
    let scene = scenes_dir().join("two_shaft_6000rpm.toml");
    let out = hbal(&[
        "sweep",
        scene.to_str().unwrap(),
        "--parameter",
        "fundamental.rpm",
        "--from",
        "5000",
        "--to",
        "7000",
        "--points",
        "3",
        "--json",
        "--no-stability",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let json = json_of(&out);
    let points = json["points"].as_array().unwrap();
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("\nrpm = 6000\n"));
    let dir = temp_dir("parameter-speed");
    let mut amplitudes = Vec::new();
    for (point, rpm) in points.iter().zip(["5000", "6000", "7000"]) {
        assert_eq!(
            point["parameter"].as_f64().unwrap(),
            rpm.parse::<f64>().unwrap()
        );
        let path = dir.join(format!("two_shaft_{rpm}.toml"));
        std::fs::write(
            &path,
            text.replace("\nrpm = 6000\n", &format!("\nrpm = {rpm}\n")),
        )
        .unwrap();
        let solved = json_of(&hbal(&[
            "solve",
            path.to_str().unwrap(),
            "--json",
            "--no-stability",
        ]));
        let want = solved["dofs"][0]["max_abs"].as_f64().unwrap();
        let got = point["max_abs"][0].as_f64().unwrap();
        assert!(
            (got - want).abs() < 1e-9 * want,
            "{rpm} rpm: {got:e} against {want:e}"
        );
        amplitudes.push(got);
    }
    let _ = std::fs::remove_dir_all(&dir);
    // The speeds give different answers (what the comparison above relies on).
    assert!(
        (amplitudes[0] - amplitudes[2]).abs() > 1e-3 * amplitudes[1],
        "{amplitudes:?}"
    );
}

/// Automatic harmonics held along a sweep: the backlash pair with forcing 0.1 from 1.6 down to
/// 0.44 rad/s starts at H = 8 and raises H where the contact opens (32, 64, 128 on the
/// quantities, the default control; 16, 32, 64 on the whole solution), so no point exceeds the
/// tolerance (before: H = 8 kept, estimates up to 4.2e-3 and a warning).
#[test]
fn sweep_raises_harmonics_along_the_branch() {
    let text = std::fs::read_to_string(scenes_dir().join("gear_backlash.toml"))
        .unwrap()
        .replace(
            "{ dof = \"x\", order = 1, cos = 0.05 }",
            "{ dof = \"x\", order = 1, cos = 0.1 }",
        )
        .replace(
            "harmonics = { count = 32 }",
            "harmonics = { auto = true, count = 8, tolerance = 1e-6 }",
        )
        .replace("rad_s = 0.7", "rad_s = 1.6");
    assert!(text.contains("auto = true") && text.contains("cos = 0.1 }"));
    let p = std::env::temp_dir().join(format!("hbal-auto-sweep-{}.toml", std::process::id()));
    std::fs::write(&p, text).unwrap();
    let out = hbal(&[
        "sweep",
        p.to_str().unwrap(),
        "--to",
        "0.44",
        "--no-stability",
        "--json",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(
        err.contains("harmonics along the branch: H = 8, H = 32 from"),
        "{err}"
    );
    assert!(!err.contains("warning"), "{err}");
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let worst = doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|p| p["worst_quantity"]["error"].as_f64())
        .fold(0.0, f64::max);
    assert!(worst > 0.0 && worst <= 1e-6, "{worst:e}");
    std::fs::remove_file(&p).ok();
}

/// Where stderr is not a terminal (a log file, CI) a sweep prints plain progress lines (every
/// 10 s by default; `HBAL_PROGRESS_EVERY` seconds here 0: every update).
#[test]
fn progress_lines_where_stderr_is_not_a_terminal() {
    let scene =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/duffing.toml");
    let sweep = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
            .args([
                "sweep",
                scene.to_str().unwrap(),
                "--to",
                "2",
                "--no-stability",
            ])
            .args(extra)
            .env("HBAL_PROGRESS_EVERY", "0")
            .output()
            .unwrap()
    };
    let out = sweep(&[]);
    assert_eq!(out.status.code(), Some(0));
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("progress: sweep "))
        .collect();
    assert!(lines.len() > 3, "{err}");
    assert!(lines.last().unwrap().contains("100 %"), "{err}");
    // With --json nothing but the document.
    let out = sweep(&["--json"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("progress:"));
}
