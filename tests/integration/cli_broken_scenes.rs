//! A catalogue of broken scenes, each with the message `hbal check` must show (naming the
//! file and the field) and exit code 2; the scene examples of docs/scenes.md are valid.

use crate::common::cli::scenes_dir;
use crate::common::hbal;
use std::path::Path;

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
