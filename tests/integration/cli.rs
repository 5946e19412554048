//! The `hbal` binary on every example scene and on a catalogue of broken scenes, each with the
//! message it must show and exit code 2.

use crate::common;

use common::hbal;

use std::path::{Path, PathBuf};
use std::process::Output;

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes")
}

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
            "gap_nan.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"gap_contact\"")
                .replace("k = 1.0", "gap = nan\nstiffness = 100.0"),
            "elements[0].gap: must be a finite number, got NaN",
        ),
        ("offset_inf.toml", GOOD.replace("k = 1.0", "k = 1.0\noffset = -inf"), "elements[0].offset: must be a finite number, got -inf"),
        ("offset_type.toml", GOOD.replace("k = 1.0", "k = 1.0\noffset = \"1 mm\""), "elements[0].offset: must be a number (m or rad)"),
        ("offset_as_type.toml", GOOD.replace("type = \"linear_spring\"", "type = \"offset\""), "elements[0].type: `offset` is not an element type"),
        (
            "stages.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"stop_spring\"").replace(
                "k = 1.0",
                "stages = [{ from = 0.0, stiffness = 400.0 }, { from = 0.3, stiffness = 50.0 }]",
            ),
            "element `spring`: parameter `stages[1].stiffness` must be >= stages[0].stiffness = 400 (a progressive spring",
        ),
        (
            "stage_field.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"stop_spring\"")
                .replace("k = 1.0", "stages = [{ from = 0.0, stifness = 400.0 }]"),
            "unknown field `stifness`",
        ),
        (
            "friction_limit.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"friction\"")
                .replace("k = 1.0", "limit = -1.0\nregularization = 0.01"),
            "element `spring`: parameter `limit` must be finite and >= 0, got -1",
        ),
        (
            "polynomial_empty.toml",
            GOOD.replace("type = \"linear_spring\"", "type = \"polynomial_spring\"")
                .replace("k = 1.0", "coefficients = []"),
            "element `spring`: parameter `coefficients` must be a non-empty list",
        ),
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
    assert!(csv
        .starts_with("rad_s,stable,fold,bifurcation,max_abs_x,amp_x_k0_order_0,amp_x_k1_order_1"));
    assert!(csv.lines().next().unwrap().ends_with(
        ",multipliers_abs,residual,truncation,fold_speed,spurious_turn,bifurcation_speed,error_estimate"
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

fn json_of(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "one JSON object on stdout ({e}): {}\nstderr: {}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hbal-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The backlash pair at W = 0.8, where Newton from the linear start finds the unstable middle
/// orbit.
fn backlash_at_08(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(scenes_dir().join("gear_backlash.toml")).unwrap();
    assert!(text.contains("rad_s = 0.7"));
    let path = dir.join("backlash_08.toml");
    std::fs::write(&path, text.replace("rad_s = 0.7", "rad_s = 0.8")).unwrap();
    path
}

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
    let out = hbal(&["solve", p, "--json", "--method", "fixed_point"]);
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
            // Laws with memory: no multipliers, stability unknown (never a wrong number).
            if scene.model.memory_element().is_some() {
                assert!(
                    points
                        .iter()
                        .all(|pt| pt["stable"].is_null() && pt["multipliers_abs"].is_null()),
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
