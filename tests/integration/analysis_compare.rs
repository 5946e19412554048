//! The library's comparison with the time domain (`hbal::analysis::compare`, issue 32) is
//! what `hbal compare --json` prints, and its errors are the engineer's numbers: the Duffing
//! oscillator's methods agree with the time domain.

use crate::common::json_diff::difference_without_times;
use hbal::analysis::{compare, CompareSettings};
use hbal::scene::Scene;
use serde_json::Value;
use std::path::Path;

fn scene_path(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenes")
        .join(name)
}

#[test]
fn the_cli_json_is_the_serialised_library_comparison() {
    for name in [
        "duffing.toml",
        "two_shaft_6000rpm.toml",
        "gear_backlash.toml",
    ] {
        let path = scene_path(name);
        let scene = Scene::load(&path).unwrap();
        let a = compare(&scene, &CompareSettings::default()).unwrap();
        let mut library: Value = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
            .args(["compare", "--json"])
            .arg(&path)
            .output()
            .unwrap();
        let mut cli: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(
            difference_without_times(&mut library, &mut cli),
            None,
            "{name}"
        );
        assert_eq!(out.status.code(), Some(a.exit_code() as i32), "{name}");
        assert_eq!(cli["schema_version"], 1);
    }
}

#[test]
fn every_method_on_the_duffing_oscillator_agrees_with_the_time_domain() {
    let scene = Scene::load(&scene_path("duffing.toml")).unwrap();
    let a = compare(&scene, &CompareSettings::default()).unwrap();
    assert_eq!(a.methods.len(), 4, "fixed point, Newton, Broyden, Anderson");
    assert!(a.started_on_hb_orbit);
    for m in &a.methods {
        assert!(m.solution.is_converged(), "{}", m.method);
        // H = 7 of a Duffing oscillator at 1.2 rad/s: the truncation is far below 1e-5.
        assert!(m.error < 1e-5, "{}: {:.2e}", m.method, m.error);
    }
    assert_eq!(a.exit_code(), 0);
    // One named method with a tolerance; an unknown one is bad input.
    let one = CompareSettings {
        methods: Some(vec!["newton".into()]),
        tolerance: Some(1e-12),
        ..CompareSettings::default()
    };
    let a = compare(&scene, &one).unwrap();
    assert_eq!(a.methods.len(), 1);
    assert!(a.methods[0].solution.residual() <= 1e-12);
    let unknown = CompareSettings {
        methods: Some(vec!["euler".into()]),
        ..CompareSettings::default()
    };
    assert_eq!(compare(&scene, &unknown).unwrap_err().exit_code(), 2);
}
