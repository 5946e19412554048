//! The library's solve analysis (`hbal::analysis::solve`, issue 32) is what `hbal solve`
//! prints: for every scene in examples/scenes the JSON of `hbal solve --json` equals, field by
//! field, the serialised library result (wall times aside), and the exit code is the
//! analysis's.

use crate::common::json_diff::difference_without_times;
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
        if scene.torus.is_some() {
            continue; // on several base frequencies: tests/integration/torus_cli.rs
        }
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
        let name = path.display();
        if let Some(d) = difference_without_times(&mut library, &mut cli) {
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

/// Automatic harmonics whose second level cannot be refined (an undamped natural frequency at
/// harmonic 16 of the H = 8 level's 2H reference): the H = 4 level that succeeded is kept and
/// reported, marked (`stopped` says why, exit 1), with the JSON on stdout.
#[test]
fn automatic_harmonics_keep_the_levels_before_one_that_fails() {
    let scene_text = r#"
description = "undamped oscillator whose 16th harmonic is resonant"
dofs = ["x"]
mass = [[1.0]]
stiffness = [[256.0]]
fundamental = { rad_s = 1.0 }
harmonics = { count = 4, auto = true }
loads = [{ dof = "x", order = 1, cos = 100.0 }]

[[elements]]
name = "spring"
type = "cubic_spring"
connects = { x = 1.0 }
k = 0.0
alpha = 200.0
"#;
    let dir = crate::common::cli::temp_dir("analysis_solve_stopped");
    let path = dir.join("stopped.toml");
    std::fs::write(&path, scene_text).unwrap();
    let scene = Scene::load(&path).unwrap();
    let a = solve(&scene, &SolveSettings::default()).unwrap();
    let auto = a.auto.as_ref().unwrap();
    let stopped = auto.stopped.as_deref().unwrap();
    assert!(
        stopped.contains("refinement of H = 8") && stopped.contains("singular at harmonic 16"),
        "{stopped}"
    );
    assert!(auto.capped);
    assert_eq!(auto.levels.len(), 1);
    assert_eq!(auto.levels[0].harmonics, 4);
    // The H = 4 level's own estimate against H = 8: about 1e-3, above the tolerance 1e-6.
    assert!(
        auto.levels[0].estimate > 1e-4 && auto.levels[0].estimate < 1e-2,
        "{}",
        auto.levels[0].estimate
    );
    assert!(a.solution.is_converged());
    assert_eq!(a.solution.basis().harmonics(), 4);
    assert_eq!(a.exit_code(), 1);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args(["solve", "--json"])
        .arg(&path)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let doc: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["auto_harmonics"]["stopped"], stopped);
    assert_eq!(doc["auto_harmonics"]["reached"], false);
    assert_eq!(doc["harmonics"], 4);
    // The report says why, as `hbal solve` does (it once said the solve did not converge).
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .arg("report")
        .arg(&path)
        .arg("--out")
        .arg(dir.join("report"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("automatic harmonics stopped before the tolerance"),
        "{err}"
    );
    assert!(!err.contains("did not converge"), "{err}");
}
