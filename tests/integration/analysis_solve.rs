//! The library's solve analysis (`hbal::analysis::solve`, issue 32) is what `hbal solve`
//! prints: for every scene in examples/scenes the JSON of `hbal solve --json` equals, field by
//! field, the serialised library result (wall times aside), and the exit code is the
//! analysis's.

use crate::common::json_diff::{first_difference, without_times};
use hbal::analysis::{solve, SolveSettings};
use hbal::scene::Scene;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// Every example scene (TOML), sorted.
pub(crate) fn scenes() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    paths.sort();
    paths
}

#[test]
fn the_cli_json_is_the_serialised_library_result_for_every_example_scene() {
    let paths = scenes();
    assert!(paths.len() >= 20, "{} scenes", paths.len());
    for path in paths {
        let scene = Scene::load(&path).unwrap();
        let analysis = solve(&scene, &SolveSettings::default()).unwrap();
        // Through text, as the CLI's: serde_json's parser may round a float's last digit.
        let mut library: Value =
            serde_json::from_str(&serde_json::to_string(&analysis).unwrap()).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
            .args(["solve", "--json"])
            .arg(&path)
            .output()
            .unwrap();
        let mut cli: Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        without_times(&mut library);
        without_times(&mut cli);
        let name = path.display();
        if let Some(d) = first_difference(&library, &cli, "") {
            panic!("{name}: {d}");
        }
        assert_eq!(
            out.status.code(),
            Some(analysis.exit_code() as i32),
            "{name}"
        );
    }
}

/// The library's typed values where the engineer reads them: the two-shaft model at 6000 rpm
/// converges, is stable, and names every DOF and element.
#[test]
fn the_two_shaft_analysis_reads_as_typed_values() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/two_shaft_6000rpm.toml");
    let scene = Scene::load(&path).unwrap();
    let a = solve(&scene, &SolveSettings::default()).unwrap();
    assert!(a.solution.is_converged());
    assert_eq!(a.stable(), Some(true));
    assert_eq!(a.exit_code(), 0);
    assert_eq!(a.max_abs.len(), scene.model.n_dofs());
    assert_eq!(
        a.elements.as_ref().unwrap().len(),
        scene.model.elements().len()
    );
    let e = a.estimate.as_ref().unwrap().as_ref().unwrap();
    assert!(e.relative > 0.0 && e.relative < 1e-2, "{}", e.relative);
    // A start with automatic harmonics is refused by the library (bad input).
    let mut auto = Scene::load(&path).unwrap();
    auto.auto = Some(hbal::solve::AutoHarmonics::default());
    let settings = SolveSettings {
        start: Some((a.solution.harmonics().to_vec(), "previous".into())),
        ..SolveSettings::default()
    };
    let err = solve(&auto, &settings).unwrap_err();
    assert!(err.to_string().contains("--start needs a fixed H"), "{err}");
}
