//! The `hbal` binary on every example scene and on a catalogue of broken scenes, each with the
//! message it must show and exit code 2.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hbal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args(args)
        .output()
        .expect("run hbal")
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes")
}

#[test]
fn every_example_scene_solves_and_checks() {
    let mut count = 0;
    for entry in std::fs::read_dir(scenes_dir()).unwrap() {
        let path = entry.unwrap().path();
        let p = path.to_str().unwrap();
        let out = hbal(&["check", p]);
        assert!(
            out.status.success(),
            "check {p}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
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
        assert!(doc["solve_seconds"].as_f64().unwrap() < 1.0);
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
    assert!(csv.starts_with("dof,order,cos,sin\ngear,0,"));
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
    }
}

const GOOD: &str = r#"
dofs = ["x"]
mass = [[1.0]]
damping = [[0.1]]
fundamental = { rad_s = 1.3 }
harmonics = { count = 3 }
loads = [{ dof = "x", order = 1, cos = 0.1 }]

[[elements]]
name = "spring"
type = "linear_spring"
connects = { x = 1.0 }
k = 1.0
"#;

fn broken(name: &str, text: &str, expected: &str) {
    let dir = std::env::temp_dir().join(format!("hbal-broken-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let out = hbal(&["check", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{name}: {err}");
    assert!(err.contains(expected), "{name}: `{err}` lacks `{expected}`");
    assert!(
        err.contains(name),
        "{name}: the message must name the file: {err}"
    );
    assert!(!err.contains("panicked"), "{name}: {err}");
}

#[test]
fn good_scene_passes_the_catalogue_baseline() {
    let dir = std::env::temp_dir();
    let path = dir.join(format!("hbal-good-{}.toml", std::process::id()));
    std::fs::write(&path, GOOD).unwrap();
    assert!(hbal(&["check", path.to_str().unwrap()]).status.success());
}

#[test]
fn broken_scenes_give_messages_that_name_file_and_field() {
    let cases: Vec<(&str, String, &str)> = vec![
        ("syntax.toml", GOOD.replace("dofs = [\"x\"]", "dofs = [\"x\""), "syntax.toml:3:1: invalid array; expected `]`"),
        ("syntax.json", "{\n \"dofs\": [\"x\"],\n \"mass\": [[1.0]\n}".into(), "syntax.json:4:"),
        ("misspelled.toml", GOOD.replace("mass =", "mas ="), "unknown field `mas`"),
        ("missing_mass.toml", GOOD.replace("mass = [[1.0]]", ""), "missing field `mass`"),
        ("unknown_type.toml", GOOD.replace("linear_spring", "linear_sprung"), "known element types: linear_spring"),
        ("law_field.toml", GOOD.replace("k = 1.0", "kk = 1.0"), "elements[0].kk: unknown field `kk`"),
        ("connects_dof.toml", GOOD.replace("connects = { x = 1.0 }", "connects = { y = 1.0 }"), "elements[0].connects: unknown DOF `y`"),
        ("load_dof.toml", GOOD.replace("dof = \"x\"", "dof = \"z\""), "loads[0].dof: unknown DOF `z`"),
        ("mass_rows.toml", GOOD.replace("mass = [[1.0]]", "mass = [[1.0], [2.0]]"), "mass: expected 1 rows"),
        ("mass_cols.toml", GOOD.replace("mass = [[1.0]]", "mass = [[1.0, 0.0]]"), "mass[0]: expected 1 columns"),
        ("mass_negative.toml", GOOD.replace("mass = [[1.0]]", "mass = [[-1.0]]"), "not symmetric positive definite"),
        ("mass_type.toml", GOOD.replace("mass = [[1.0]]", "mass = \"heavy\""), "mass: invalid type"),
        ("negative_k.toml", GOOD.replace("k = 1.0", "k = -1.0"), "parameter `k` must be finite and >= 0"),
        (
            "negative_backlash.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"backlash\"")
                .replace("k = 1.0", "half_backlash = -0.5\nstiffness = { shape = \"constant\", stiffness = 1.0 }"),
            "half_backlash",
        ),
        (
            "contact_ratio.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"mesh_stiffness\"").replace(
                "k = 1.0",
                "teeth = 1\nprofile = { shape = \"rectangular\", one_tooth = 1.0, two_tooth = 2.0, contact_ratio = 2.5 }",
            ),
            "contact_ratio` must be in [1, 2]",
        ),
        (
            "teeth.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"mesh_stiffness\"")
                .replace("k = 1.0", "teeth = 0\nprofile = { shape = \"constant\", stiffness = 1.0 }"),
            "teeth",
        ),
        (
            "shape.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"mesh_stiffness\"")
                .replace("k = 1.0", "teeth = 1\nprofile = { shape = \"triangle\", mean = 1.0 }"),
            "unknown variant `triangle`",
        ),
        ("two_units.toml", GOOD.replace("{ rad_s = 1.3 }", "{ rad_s = 1.3, rpm = 60 }"), "fundamental: give exactly one of"),
        ("negative_speed.toml", GOOD.replace("{ rad_s = 1.3 }", "{ rpm = -600 }"), "fundamental: must be finite and > 0"),
        ("samples.toml", GOOD.replace("{ count = 3 }", "{ count = 3, samples = 4 }"), "harmonics.samples"),
        ("load_order.toml", GOOD.replace("order = 1", "order = 5"), "order 5 but only 3 harmonics"),
        ("method.toml", format!("{GOOD}\n[solver]\nmethod = \"newtn\"\n"), "solver.method: unknown method `newtn`"),
        ("solver_field.toml", format!("{GOOD}\n[solver]\ntolerence = 1e-8\n"), "solver.tolerence: unknown field `tolerence`, expected one of"),
        ("gamma.toml", format!("{GOOD}\n[solver]\nmethod = \"fixed_point\"\ngamma = 1.5\n"), "solver.gamma"),
        ("nan.toml", GOOD.replace("k = 1.0", "k = nan"), "elements[0].k: must be a finite number, got NaN"),
        ("empty_dofs.toml", GOOD.replace("dofs = [\"x\"]", "dofs = []"), "dofs: at least one DOF is required"),
        (
            "nested_variant.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"mesh_stiffness\"")
                .replace("k = 1.0", "teeth = 1\nprofile = { shape = \"constant\", stiffness = 1.0 }\ndamping = { proportinal = 1e-3 }"),
            "elements[0].damping.proportinal: unknown variant `proportinal`",
        ),
        (
            "nested_field.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"mesh_stiffness\"")
                .replace("k = 1.0", "teeth = 1\nprofile = { shape = \"rectangular\", one_toth = 1.0, two_tooth = 2.0, contact_ratio = 1.5 }"),
            "elements[0].profile.one_toth: unknown field `one_toth`",
        ),
        ("no_connects.toml", GOOD.replace("connects = { x = 1.0 }", ""), "elements[0]: missing field `connects`"),
        ("no_type.toml", GOOD.replace("type = \"linear_spring\"", ""), "elements[0]: missing field `type`"),
        (
            "resonance.toml",
            GOOD.replace("damping = [[0.1]]", "").replace("{ rad_s = 1.3 }", "{ rad_s = 0.5 }"),
            "singular at harmonic 2",
        ),
    ];
    assert!(cases.len() >= 20);
    for (name, text, expected) in &cases {
        broken(name, text, expected);
    }
    // A missing file and a bad command-line method.
    let out = hbal(&["check", "no/such/scene.toml"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("no/such/scene.toml: cannot read the file")
    );
    let scene = scenes_dir().join("duffing.toml");
    let out = hbal(&["solve", scene.to_str().unwrap(), "--method", "bogus"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown method `bogus`"));
}

/// Every TOML and JSON example in docs/scenes.md is a complete scene that checks and solves.
#[test]
fn documented_examples_are_valid_scenes() {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes.md"))
        .unwrap();
    let dir = std::env::temp_dir().join(format!("hbal-doc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut count = 0;
    for (lang, ext) in [("```toml", "toml"), ("```json", "json")] {
        for (i, block) in doc.split(lang).skip(1).enumerate() {
            let body = block.split("```").next().unwrap();
            let path = dir.join(format!("doc{i}.{ext}"));
            std::fs::write(&path, body).unwrap();
            let out = hbal(&["solve", path.to_str().unwrap(), "--json"]);
            assert_eq!(
                out.status.code(),
                Some(0),
                "docs example {ext} #{i}: {}{}",
                String::from_utf8_lossy(&out.stderr),
                body
            );
            count += 1;
        }
    }
    assert!(count >= 6, "{count} examples");
}

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
    let csv = std::fs::read_to_string(dir.join("branch.csv")).unwrap();
    assert!(csv.starts_with("rad_s,stable,fold,bifurcation,max_abs_x,amp_x_0"));
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
