//! FE import in scene files: structural matrices from Matrix Market files (general and symmetric
//! storage) and inline triplets, DOF names from a sidecar list or generated. The model and its
//! periodic solution equal those of the same scene given densely (bad input:
//! `matrix_import_bad_input`).

use hbal::nalgebra::DMatrix;
use hbal::scene::Scene;
use hbal::{HarmonicBalance, Newton};
use std::path::{Path, PathBuf};

/// The symmetric 3-DOF chain with backlash (examples/scenes/chain_backlash.toml at W = 1.33,
/// H = 32, where Newton converges from the linear solution), without its matrices and DOFs.
const REST: &str = r#"
fundamental = { rad_s = 1.33 }
harmonics = { count = 32 }
loads = [{ dof = "x1", order = 1, cos = 1.0 }]

[[elements]]
name = "contact"
type = "backlash"
connects = { x2 = -1.0, x3 = 1.0 }
half_backlash = 1.0
stiffness = { shape = "constant", stiffness = 5.0 }
"#;

const DENSE: &str = r#"
dofs = ["x1", "x2", "x3"]
mass = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
damping = [[0.1, -0.04, 0.0], [-0.04, 0.1, -0.04], [0.0, -0.04, 0.06]]
stiffness = [[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]]
"#;

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/mtx")
}

/// A fresh directory for one test's files.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hbal-mtx-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `files` (name, text) and a scene `scene.toml` into a fresh directory; returns the
/// scene's path.
pub(crate) fn scene_with_files(test: &str, scene: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = temp_dir(test);
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    path
}

fn relative(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax().max(f64::MIN_POSITIVE)
}

/// The converged harmonics of a scene's model (Newton, tolerance 1e-13).
fn harmonics(scene: &Scene) -> Vec<hbal::num_complex::Complex64> {
    let hb = HarmonicBalance::new(&scene.model, scene.basis).unwrap();
    let sol = Newton::new()
        .with_tolerance(1e-13)
        .unwrap()
        .solve(&hb, &mut hb.workspace())
        .unwrap();
    assert!(sol.is_converged(), "{}: {}", scene.file, sol.termination);
    sol.harmonics().to_vec()
}

/// Same matrices, same DOFs, same periodic solution (to 1e-14) as the dense scene.
fn assert_equals_dense(scene: &Scene) {
    let dense = Scene::from_str(&format!("{DENSE}{REST}"), "dense.toml").unwrap();
    let (a, b) = (&scene.model, &dense.model);
    assert_eq!(a.dof_names(), b.dof_names(), "{}", scene.file);
    for (what, x, y) in [
        ("mass", a.mass().to_dense(), b.mass().to_dense()),
        ("k0", a.k0().to_dense(), b.k0().to_dense()),
        ("d0", a.d0().to_dense(), b.d0().to_dense()),
        (
            "structural damping",
            a.structural_damping().to_dense(),
            b.structural_damping().to_dense(),
        ),
    ] {
        let d = relative(&x, &y);
        assert!(d <= 1e-14, "{}: {what} differs by {d:e}", scene.file);
    }
    let (ha, hb) = (harmonics(scene), harmonics(&dense));
    let scale = hb.iter().map(|c| c.norm()).fold(0.0, f64::max);
    let d = ha
        .iter()
        .zip(&hb)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max);
    assert!(
        d <= 1e-14 * scale,
        "{}: harmonics differ by {d:e}",
        scene.file
    );
}

#[test]
fn matrix_market_files_give_the_dense_model() {
    let dir = data_dir();
    let dir = dir.to_str().unwrap();
    // General storage (stiffness) and symmetric storage (an integer mass), a sidecar DOF list,
    // absolute paths.
    let general = format!(
        "dofs = {{ file = \"{dir}/dofs.txt\" }}\n\
         mass = {{ file = \"{dir}/mass_integer.mtx\" }}\n\
         damping = {{ file = \"{dir}/damping_general.mtx\" }}\n\
         stiffness = {{ file = \"{dir}/stiffness_general.mtx\" }}\n{REST}"
    );
    assert_equals_dense(&Scene::from_str(&general, "general.toml").unwrap());
    // Symmetric storage with a repeated position, paths relative to the scene file.
    let symmetric = format!(
        "dofs = [\"x1\", \"x2\", \"x3\"]\n\
         mass = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\n\
         damping = {{ file = \"damping_general.mtx\" }}\n\
         stiffness = {{ file = \"stiffness_symmetric.mtx\" }}\n{REST}"
    );
    let path = data_dir().join("symmetric.toml");
    let scene = Scene::from_str(&symmetric, path.to_str().unwrap()).unwrap();
    assert_equals_dense(&scene);
    // `Scene::load` resolves against the scene's directory too.
    let loaded = Scene::load(&scene_with_files("load", &symmetric, &[])).unwrap_err();
    assert!(
        loaded.to_string().contains("damping_general.mtx"),
        "{loaded}"
    );
    let stiffness = std::fs::read_to_string(data_dir().join("stiffness_symmetric.mtx")).unwrap();
    let damping = std::fs::read_to_string(data_dir().join("damping_general.mtx")).unwrap();
    let path = scene_with_files(
        "load_ok",
        &symmetric,
        &[
            ("stiffness_symmetric.mtx", &stiffness),
            // Windows line ends.
            ("damping_general.mtx", &damping.replace('\n', "\r\n")),
        ],
    );
    assert_equals_dense(&Scene::load(&path).unwrap());
}

#[test]
fn relative_paths_of_a_scene_text_without_a_directory_are_taken_from_the_current_directory() {
    // `cargo test` runs in the package root.
    let text = format!(
        "dofs = {{ file = \"tests/data/mtx/dofs.txt\" }}\n\
         mass = {{ file = \"tests/data/mtx/mass_integer.mtx\" }}\n\
         damping = {{ file = \"tests/data/mtx/damping_general.mtx\" }}\n\
         stiffness = {{ file = \"tests/data/mtx/stiffness_symmetric.mtx\" }}\n{REST}"
    );
    assert_equals_dense(&Scene::from_str(&text, "scene.toml").unwrap());
    assert_equals_dense(&Scene::from_str(&text, "no/such/directory/scene.toml").unwrap());
}

#[test]
fn inline_triplets_give_the_dense_model() {
    // General triplets with repeated positions; symmetric = true with the upper triangle.
    let toml = format!(
        "dofs = [\"x1\", \"x2\", \"x3\"]\n\
         mass = {{ triplets = [[1, 1, 0.5], [2, 2, 1.0], [3, 3, 1.0], [1, 1, 0.5]] }}\n\
         damping = {{ triplets = [[1, 1, 0.1], [1, 2, -0.04], [2, 1, -0.04], [2, 2, 0.1], \
                                  [2, 3, -0.04], [3, 2, -0.04], [3, 3, 0.06]] }}\n\
         stiffness = {{ triplets = [[1, 1, 2.0], [1, 2, -1.0], [2, 2, 2.0], [2, 3, -1.0], \
                                    [3, 3, 1.0]], symmetric = true }}\n{REST}"
    );
    assert_equals_dense(&Scene::from_str(&toml, "triplets.toml").unwrap());
    // The same in JSON, lower triangle.
    let json = r#"{
      "dofs": ["x1", "x2", "x3"],
      "mass": {"triplets": [[1, 1, 1], [2, 2, 1], [3, 3, 1]], "symmetric": true},
      "damping": [[0.1, -0.04, 0.0], [-0.04, 0.1, -0.04], [0.0, -0.04, 0.06]],
      "stiffness": {"triplets": [[1, 1, 2], [2, 1, -1], [2, 2, 2], [3, 2, -1], [3, 3, 1]],
                    "symmetric": true},
      "fundamental": {"rad_s": 1.33}, "harmonics": {"count": 32},
      "loads": [{"dof": "x1", "order": 1, "cos": 1.0}],
      "elements": [{"name": "contact", "type": "backlash", "connects": {"x2": -1.0, "x3": 1.0},
                    "half_backlash": 1.0, "stiffness": {"shape": "constant", "stiffness": 5.0}}]
    }"#;
    assert_equals_dense(&Scene::from_str(json, "triplets.json").unwrap());
    // A triplet value is a scene number: `--parameter` can sweep it.
    let mut doc = Scene::parse_value(&toml, "triplets.toml").unwrap();
    hbal::scene::set_parameter(&mut doc, "stiffness.triplets[0][2]", 3.0).unwrap();
    let scene = Scene::from_value(doc, "triplets.toml").unwrap();
    assert_eq!(scene.model.k0().get(0, 0), 3.0);
}

#[test]
fn generated_and_sidecar_dof_names() {
    let chain = |dofs: &str| {
        format!(
            "dofs = {dofs}\nmass = {{ triplets = [[1, 1, 1.0], [2, 2, 1.0], [3, 3, 1.0]] }}\n\
             fundamental = {{ rad_s = 1.0 }}\nharmonics = {{ count = 1 }}\n"
        )
    };
    let names = |dofs: &str, file: &str| -> Vec<String> {
        Scene::from_str(&chain(dofs), file)
            .unwrap()
            .model
            .dof_names()
            .to_vec()
    };
    assert_eq!(
        names("{ count = 3, prefix = \"shaft\" }", "a.toml"),
        ["shaft.1", "shaft.2", "shaft.3"]
    );
    assert_eq!(
        names("{ count = 3 }", "a.toml"),
        ["dof.1", "dof.2", "dof.3"]
    );
    // Numbered from 0, as openTorsion and most shaft-line tools number their nodes.
    assert_eq!(
        names("{ count = 3, prefix = \"node\", first = 0 }", "a.toml"),
        ["node.0", "node.1", "node.2"]
    );
    let scene = data_dir().join("scene.toml");
    assert_eq!(
        names("{ file = \"dofs.txt\" }", scene.to_str().unwrap()),
        ["x1", "x2", "x3"]
    );
    // Loads and elements refer to generated names.
    let text = chain("{ count = 3, prefix = \"shaft\" }")
        + "loads = [{ dof = \"shaft.3\", order = 1, cos = 1.0 }]\n";
    let scene = Scene::from_str(&text, "a.toml").unwrap();
    assert_eq!(scene.model.loads()[0].dof, 2);
    // An unknown name among many: the message lists a few and the count.
    let big = "dofs = { count = 20, prefix = \"s\" }\n\
               mass = { triplets = [] }\n\
               fundamental = { rad_s = 1.0 }\nharmonics = { count = 1 }\n\
               loads = [{ dof = \"s.21\", order = 1, cos = 1.0 }]\n";
    let err = Scene::from_str(big, "big.toml").unwrap_err().to_string();
    assert!(
        err.contains("loads[0].dof: unknown DOF `s.21` (the scene has: s.1, s.2,")
            && err.contains("(20 in all (from dofs.count))"),
        "{err}"
    );
}

/// A 1000-DOF chain from Matrix Market files and generated names: read and built quickly
/// (the time is printed; `cargo test --release --test integration -- matrix_import:: --nocapture`).
#[test]
fn a_thousand_dof_chain_reads_quickly() {
    let n = 1000;
    let mut k = format!(
        "%%MatrixMarket matrix coordinate real symmetric\n% chain of {n} unit springs\n{n} {n} {}\n",
        2 * n - 1
    );
    let mut m = format!("%%MatrixMarket matrix coordinate real general\n{n} {n} {n}\n");
    for i in 1..=n {
        k += &format!("{i} {i} {}\n", if i == n { 1.0 } else { 2.0 });
        if i > 1 {
            k += &format!("{i} {} -1.0\n", i - 1);
        }
        m += &format!("{i} {i} 1.0e-3\n");
    }
    let scene = format!(
        "dofs = {{ count = {n}, prefix = \"shaft\" }}\nmass = {{ file = \"m.mtx\" }}\n\
         stiffness = {{ file = \"k.mtx\" }}\nfundamental = {{ rad_s = 1.0 }}\n\
         harmonics = {{ count = 1 }}\nloads = [{{ dof = \"shaft.{n}\", order = 1, cos = 1.0 }}]\n"
    );
    let path = scene_with_files("big", &scene, &[("m.mtx", &m), ("k.mtx", &k)]);
    let start = std::time::Instant::now();
    let read = hbal::scene::matrix_market::read(&path.with_file_name("k.mtx")).unwrap();
    let t_read = start.elapsed();
    assert_eq!(read.entries.len(), 3 * n - 2);
    let start = std::time::Instant::now();
    let scene = Scene::load(&path).unwrap();
    let t_load = start.elapsed();
    let k0 = scene.model.k0();
    assert_eq!(
        (k0.get(0, 0), k0.get(1, 0), k0.get(n - 1, n - 1)),
        (2.0, -1.0, 1.0)
    );
    assert_eq!(scene.model.dof_names()[n - 1], format!("shaft.{n}"));
    // The share of the model builder: assembly, symmetry check, sparse Cholesky.
    let names: Vec<&str> = scene.model.dof_names().iter().map(String::as_str).collect();
    let start = std::time::Instant::now();
    hbal::Model::builder(&names)
        .mass(scene.model.mass().to_dense())
        .stiffness_triplets(&read.entries)
        .build()
        .unwrap();
    let t_build = start.elapsed();
    println!(
        "{n}-DOF chain: stiffness.mtx ({} bytes) read in {:.3} ms; the whole scene (2 files) \
         loaded in {:.1} ms, of which {:.1} ms in ModelBuilder::build",
        k.len(),
        t_read.as_secs_f64() * 1e3,
        t_load.as_secs_f64() * 1e3,
        t_build.as_secs_f64() * 1e3
    );
    assert!(t_load.as_secs_f64() < 20.0, "{t_load:?}");
}
