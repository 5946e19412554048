//! FE import's bad input: every kind of broken Matrix Market file, DOF list or triplet gives a
//! message naming the file and the line (or the field and the DOF), and `hbal` exits with 2.

use super::matrix_import::scene_with_files;
use crate::common::hbal;
use hbal::scene::Scene;
use std::path::Path;

/// A 3-DOF scene around `mass`/`stiffness`/`dofs` lines, for the bad-input catalogue.
fn bad_scene(dofs: &str, mass: &str, stiffness: &str) -> String {
    format!(
        "dofs = {dofs}\nmass = {mass}\nstiffness = {stiffness}\n\
         fundamental = {{ rad_s = 1.0 }}\nharmonics = {{ count = 1 }}\n"
    )
}

const DOFS: &str = r#"["x1", "x2", "x3"]"#;
const MASS: &str = "{ file = \"m.mtx\" }";
const STIFFNESS: &str = "{ file = \"k.mtx\" }";
const GOOD_MASS: &str =
    "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n1 1 1\n2 2 1\n3 3 1\n";
const GOOD_K: &str =
    "%%MatrixMarket matrix coordinate real general\n% K\n3 3 3\n1 1 2\n2 2 2\n3 3 1\n";

/// Each case: name, scene text, files, the pieces its message must contain.
type Case = (
    &'static str,
    String,
    Vec<(&'static str, String)>,
    Vec<String>,
);

fn with_k(k: &str) -> Vec<(&'static str, String)> {
    vec![("m.mtx", GOOD_MASS.into()), ("k.mtx", k.into())]
}

fn header(kind: &str) -> String {
    format!("%%MatrixMarket matrix {kind}\n3 3 1\n1 1 1\n")
}

fn cases() -> Vec<Case> {
    let s = |x: &str| x.to_string();
    let scene = bad_scene(DOFS, MASS, STIFFNESS);
    let mut cases: Vec<Case> = vec![
        (
            "missing_file",
            bad_scene(DOFS, MASS, "{ file = \"nope.mtx\" }"),
            with_k(GOOD_K),
            vec![s("stiffness.file: "), s("nope.mtx: cannot read the Matrix Market file")],
        ),
        (
            "not_mtx",
            scene.clone(),
            with_k("3 3 1\n1 1 1\n"),
            vec![s("k.mtx:1: not a Matrix Market file"), s("got `3 3 1`")],
        ),
        (
            "empty_file",
            scene.clone(),
            with_k(""),
            vec![s("k.mtx:1: not a Matrix Market file")],
        ),
        (
            "short_header",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real\n3 3 1\n1 1 1\n"),
            vec![s("k.mtx:1: unsupported Matrix Market type"), s("expected 4 words")],
        ),
        (
            "no_size_line",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n% nothing\n"),
            vec![s("k.mtx:2: the file ends before the size line")],
        ),
        (
            "bad_size_line",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3\n1 1 1\n"),
            vec![s("k.mtx:2: expected the size line `rows columns entries`"), s("got `3 3`")],
        ),
        (
            "malformed_entry",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 2\n1 1 1.0\n2 2\n"),
            vec![s("k.mtx:4: expected an entry `row column value`, got `2 2`")],
        ),
        (
            "bad_index",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 1\n1.5 1 1.0\n"),
            vec![s("k.mtx:3: row index `1.5` is not a whole number")],
        ),
        (
            "bad_value",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 1\n1 1 stiff\n"),
            vec![s("k.mtx:3: value `stiff` is not a number")],
        ),
        (
            "bad_integer",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate integer general\n3 3 1\n1 1 1.5\n"),
            vec![s("k.mtx:3: value `1.5` is not an integer (the header says `integer`)")],
        ),
        (
            "index_out_of_range",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 2\n1 1 1.0\n3 4 1.0\n"),
            vec![s("k.mtx:4: column 4 is outside 1..=3")],
        ),
        (
            "index_zero",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 1\n0 1 1.0\n"),
            vec![s("k.mtx:3: row 0 is outside 1..=3"), s("1-based")],
        ),
        (
            "upper_triangle",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real symmetric\n3 3 2\n1 1 1.0\n1 2 1.0\n"),
            vec![s("k.mtx:4: entry (1, 2) lies above the diagonal")],
        ),
        (
            "too_few_entries",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 3\n1 1 1.0\n2 2 1.0\n"),
            vec![s("k.mtx:4: the file ends after 2 of the 3 entries declared on line 2")],
        ),
        (
            "too_many_entries",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 1\n1 1 1.0\n2 2 1.0\n"),
            vec![s("k.mtx:4: more entries than the 1 declared on line 2")],
        ),
        (
            "nan",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 1\n1 1 NaN\n"),
            vec![s("k.mtx:3: value `NaN` is not finite")],
        ),
        (
            "overflow",
            scene.clone(),
            with_k("%%MatrixMarket matrix coordinate real general\n3 3 2\n1 1 1\n2 2 -1e999\n"),
            vec![s("k.mtx:4: value `-1e999` is not finite")],
        ),
        (
            "five_for_four",
            bad_scene(r#"["a", "b", "c", "d"]"#, "{ triplets = [[1, 1, 1], [2, 2, 1], [3, 3, 1], [4, 4, 1]] }", STIFFNESS),
            with_k("%%MatrixMarket matrix coordinate real general\n5 5 1\n5 5 1.0\n"),
            vec![s("stiffness.file: "), s("k.mtx:2: the matrix is 5 x 5, but the scene has 4 DOFs")],
        ),
        (
            "sidecar_count",
            bad_scene("{ file = \"dofs.txt\" }", MASS, STIFFNESS),
            vec![
                ("m.mtx", GOOD_MASS.into()),
                ("k.mtx", GOOD_K.into()),
                ("dofs.txt", "x1\nx2\nx3\nx4\n".into()),
            ],
            vec![
                s("mass.file: "),
                s("m.mtx:2: the matrix is 3 x 3, but the scene has 4 DOFs (from "),
                s("dofs.txt)"),
            ],
        ),
        (
            "sidecar_duplicate",
            bad_scene("{ file = \"dofs.txt\" }", MASS, STIFFNESS),
            vec![
                ("m.mtx", GOOD_MASS.into()),
                ("k.mtx", GOOD_K.into()),
                ("dofs.txt", "# names\nx1\nx2 # middle\n\nx2\n".into()),
            ],
            vec![s("dofs.file: "), s("dofs.txt:5: DOF `x2` appears twice (first on line 3)")],
        ),
        (
            "sidecar_missing",
            bad_scene("{ file = \"dofs.txt\" }", MASS, STIFFNESS),
            with_k(GOOD_K),
            vec![s("dofs.file: "), s("dofs.txt: cannot read the DOF list")],
        ),
        (
            "sidecar_empty",
            bad_scene("{ file = \"dofs.txt\" }", MASS, STIFFNESS),
            vec![("dofs.txt", "# nothing\n\n".into())],
            vec![s("dofs.file: at least one DOF is required (from "), s("dofs.txt)")],
        ),
        (
            "asymmetric_mass",
            scene.clone(),
            vec![
                (
                    "m.mtx",
                    "%%MatrixMarket matrix coordinate real general\n3 3 4\n1 1 1\n2 2 1\n3 3 1\n3 1 0.25\n"
                        .into(),
                ),
                ("k.mtx", GOOD_K.into()),
            ],
            vec![
                s("mass.file: mass matrix is not symmetric positive definite: not symmetric"),
                s("(the mass matrix from "),
                s("m.mtx)"),
                s("; row 3, column 1 is 2.5e-1 but row 1, column 3 is 0e0 (1-based)"),
            ],
        ),
        (
            "singular_mass",
            scene.clone(),
            vec![
                ("m.mtx", "%%MatrixMarket matrix coordinate real symmetric\n3 3 2\n1 1 1\n2 2 1\n".into()),
                ("k.mtx", GOOD_K.into()),
            ],
            vec![s("mass.file: mass matrix is not symmetric positive definite: Cholesky"), s("m.mtx)")],
        ),
        (
            "triplet_out_of_range",
            bad_scene(DOFS, "{ triplets = [[1, 1, 1.0], [4, 4, 1.0]] }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.triplets[1]: row 4 is outside the 3 DOFs (indices 1 to 3)")],
        ),
        (
            "triplet_zero",
            bad_scene(DOFS, "{ triplets = [[1, 0, 1.0]] }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.triplets[0]: column must be a whole number ≥ 1 (indices are 1-based), got 0")],
        ),
        (
            "triplet_float_index",
            bad_scene(DOFS, "{ triplets = [[1.0, 1, 1.0]] }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.triplets[0]: row must be a whole number ≥ 1"), s("got 1.0")],
        ),
        (
            "triplet_shape",
            bad_scene(DOFS, "{ triplets = [[1, 1]] }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.triplets[0]: expected [row, column, value], got [1,1]")],
        ),
        (
            "triplet_value",
            bad_scene(DOFS, "{ triplets = [[1, 1, \"heavy\"]] }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.triplets[0]: value must be a finite number, got \"heavy\"")],
        ),
        (
            "triplet_nan",
            bad_scene(DOFS, "{ triplets = [[1, 1, nan]] }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.triplets[0][2]: must be a finite number, got NaN")],
        ),
        (
            "triplet_both_triangles",
            bad_scene(
                DOFS,
                MASS,
                "{ triplets = [[1, 1, 2.0], [1, 2, -1.0], [3, 3, 1.0], [2, 1, -1.0]], symmetric = true }",
            ),
            with_k(GOOD_K),
            vec![s(
                "stiffness.triplets[3]: with `symmetric = true` give one triangle only, but \
                 triplets[1] lies above the diagonal and triplets[3] below it",
            )],
        ),
        (
            "file_and_triplets",
            bad_scene(DOFS, "{ file = \"m.mtx\", triplets = [] }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass: give exactly one of `file` (a Matrix Market file) and `triplets`")],
        ),
        (
            "symmetric_file",
            bad_scene(DOFS, "{ file = \"m.mtx\", symmetric = true }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.symmetric: applies to `triplets` only")],
        ),
        (
            "misspelled_file",
            bad_scene(DOFS, "{ fiel = \"m.mtx\" }", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass.fiel: unknown field `fiel`, expected one of `file`, `triplets`, `symmetric`")],
        ),
        (
            "matrix_type",
            bad_scene(DOFS, "3.0", STIFFNESS),
            with_k(GOOD_K),
            vec![s("mass: invalid type: number `3.0`, expected a list of rows")],
        ),
        (
            "dofs_count_zero",
            bad_scene("{ count = 0 }", "{ triplets = [] }", "{ triplets = [] }"),
            vec![],
            vec![s("dofs.count: at least one DOF is required")],
        ),
        (
            "dofs_file_and_count",
            bad_scene("{ file = \"dofs.txt\", count = 3 }", MASS, STIFFNESS),
            with_k(GOOD_K),
            vec![s("dofs: give a list of names, `{ file = \"dofs.txt\" }`")],
        ),
        (
            "dofs_prefix_with_file",
            bad_scene("{ file = \"dofs.txt\", prefix = \"x\" }", MASS, STIFFNESS),
            with_k(GOOD_K),
            vec![s("dofs.prefix: applies to `count` only")],
        ),
        (
            "dofs_first_with_file",
            bad_scene("{ file = \"dofs.txt\", first = 0 }", MASS, STIFFNESS),
            with_k(GOOD_K),
            vec![s("dofs.first: applies to `count` only")],
        ),
        (
            "dofs_first_two",
            bad_scene("{ count = 3, first = 2 }", MASS, STIFFNESS),
            with_k(GOOD_K),
            vec![s("dofs.first: must be 0 or 1 (the number of the first name), got 2")],
        ),
        (
            "dofs_unknown_field",
            bad_scene("{ cuont = 3 }", MASS, STIFFNESS),
            with_k(GOOD_K),
            vec![s("dofs.cuont: unknown field `cuont`")],
        ),
    ];
    for (kind, words) in [
        ("coordinate complex general", "complex values"),
        (
            "coordinate pattern general",
            "a `pattern` file has no values",
        ),
        ("array real general", "dense `array` storage"),
        ("coordinate real hermitian", "hermitian storage"),
        ("coordinate real skew-symmetric", "skew-symmetric storage"),
        ("vector coordinate real general", "expected 4 words"),
    ] {
        cases.push((
            "unsupported",
            scene.clone(),
            with_k(&header(kind)),
            vec![
                format!(
                    "stiffness.file: {{dir}}k.mtx:1: unsupported Matrix Market type in \
                     `%%MatrixMarket matrix {kind}`: {words}"
                ),
                s("hbal reads `%%MatrixMarket matrix coordinate real general`"),
            ],
        ));
    }
    cases
}

#[test]
fn bad_input_names_the_file_and_the_line() {
    for (k, (name, scene, files, expected)) in cases().into_iter().enumerate() {
        let files: Vec<(&str, &str)> = files.iter().map(|(n, t)| (*n, t.as_str())).collect();
        let path = scene_with_files(&format!("bad{k}"), &scene, &files);
        let dir = format!("{}/", path.parent().unwrap().display());
        let err = Scene::load(&path).unwrap_err().to_string();
        assert!(
            err.starts_with(&path.display().to_string()),
            "{name}: the message must name the scene: {err}"
        );
        for piece in expected {
            let piece = piece.replace("{dir}", &dir);
            assert!(err.contains(&piece), "{name}: `{err}` lacks `{piece}`");
        }
    }
}

#[test]
fn cli_solves_the_example_and_refuses_bad_files_with_exit_code_2() {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/chain_mtx.toml");
    let p = example.to_str().unwrap();
    for command in ["check", "solve"] {
        let out = hbal(&[command, p]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{command}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let out = hbal(&["solve", p, "--json", "--no-stability"]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["converged"], true);
    assert_eq!(doc["dofs"][2]["name"], "x3");

    // The example's matrices equal chain_backlash.toml's.
    let mtx = Scene::load(&example).unwrap();
    let dense = Scene::load(&example.with_file_name("chain_backlash.toml")).unwrap();
    assert_eq!(mtx.model.mass(), dense.model.mass());
    assert_eq!(mtx.model.k0(), dense.model.k0());
    assert_eq!(mtx.model.d0(), dense.model.d0());

    let path = scene_with_files(
        "cli",
        &bad_scene(DOFS, MASS, STIFFNESS),
        &with_k("%%MatrixMarket matrix coordinate real general\n% K\n3 3 1\n1 x 2.0\n")
            .iter()
            .map(|(n, t)| (*n, t.as_str()))
            .collect::<Vec<_>>(),
    );
    for command in ["check", "solve"] {
        let out = hbal(&[command, path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{command}: {err}");
        assert!(
            err.contains("k.mtx:4: column index `x` is not a whole number"),
            "{command}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}
