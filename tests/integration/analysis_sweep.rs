//! The library's sweep analysis (`hbal::analysis::sweep`, issue 32) is what `hbal sweep`
//! prints: for every scene in examples/scenes the JSON of `hbal sweep --json` equals, field by
//! field, the serialised library result (wall times aside), and the exit code is the
//! analysis's; a cancelled sweep keeps its points and is marked; progress reaches the
//! observer.

use crate::analysis_solve::scenes;
use crate::common::json_diff::difference_without_times;
use hbal::analysis::{sweep, Observer, Silent, SweepSettings};
use hbal::continuation::{BranchStop, Cancel};
use hbal::scene::Scene;
use serde_json::Value;
use std::path::Path;

/// The library's and the CLI's sweep of `path` from the scene's speed to 5 % above it, at
/// most `max_points` points, compared field by field.
fn library_equals_cli(path: &Path, max_points: usize) {
    let scene = Scene::load(path).unwrap();
    let to = 1.05 * scene.basis.omega() / scene.omega_per_speed;
    let settings = SweepSettings {
        max_points: Some(max_points),
        ..SweepSettings::to(to)
    };
    let analysis = sweep(&scene, &settings, &mut Silent).unwrap();
    let mut library: Value =
        serde_json::from_str(&serde_json::to_string(&analysis).unwrap()).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args(["sweep", "--json", "--max-points", &max_points.to_string()])
        .args(["--to", &to.to_string()])
        .arg(path)
        .output()
        .unwrap();
    let name = path.display();
    let mut cli: Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{name}: {e}"));
    if let Some(d) = difference_without_times(&mut library, &mut cli) {
        panic!("{name}: {d}");
    }
    assert_eq!(cli["schema_version"], 1, "{name}");
    assert!(!analysis.branch.points.is_empty(), "{name}");
    assert_eq!(
        out.status.code(),
        Some(analysis.exit_code() as i32),
        "{name}"
    );
}

#[test]
fn the_cli_json_is_the_serialised_library_sweep_for_every_example_scene() {
    let paths: Vec<_> = scenes()
        .into_iter()
        .filter(|p| !p.ends_with("car_drivetrain_two_stage.toml"))
        // On several base frequencies: tests/integration/torus_cli.rs.
        .filter(|p| Scene::load(p).unwrap().torus.is_none())
        .collect();
    assert!(paths.len() >= 19, "{} scenes", paths.len());
    for path in paths {
        library_equals_cli(&path, 12);
    }
}

/// The car drivetrain's first point alone takes 18 s in the dev profile: in release.
#[test]
#[ignore]
fn the_car_drivetrain_sweep_is_the_serialised_library_sweep() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/car_drivetrain_two_stage.toml");
    library_equals_cli(&path, 4);
}

/// Progress fractions and a cancellation after the third of them.
struct CancelAfter {
    fractions: Vec<f64>,
    cancel: Cancel,
}

impl Observer for CancelAfter {
    fn progress(&mut self, fraction: f64) {
        self.fractions.push(fraction);
        if self.fractions.len() == 3 {
            self.cancel.cancel();
        }
    }
}

#[test]
fn a_cancelled_sweep_keeps_its_points_and_is_marked() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/duffing.toml");
    let scene = Scene::load(&path).unwrap();
    let cancel = Cancel::new();
    let settings = SweepSettings {
        from: Some(0.5),
        cancel: cancel.clone(),
        ..SweepSettings::to(2.6)
    };
    let mut observer = CancelAfter {
        fractions: Vec::new(),
        cancel,
    };
    let a = sweep(&scene, &settings, &mut observer).unwrap();
    let last = a.branch.points.last().unwrap().omega;
    assert_eq!(a.branch.stop, BranchStop::Cancelled { parameter: last });
    assert_eq!(observer.fractions.len(), 3, "{:?}", observer.fractions);
    assert!(observer.fractions.windows(2).all(|w| w[1] >= w[0]));
    assert!(a.branch.points.len() >= 3 && last < 2.6, "{last}");
    assert_eq!(a.exit_code(), 1);
    assert!(a.to_json()["stop"]
        .as_str()
        .unwrap()
        .starts_with("cancelled"));
    // Uncancelled, the same sweep reaches the end.
    let full = sweep(
        &scene,
        &SweepSettings {
            from: Some(0.5),
            ..SweepSettings::to(2.6)
        },
        &mut Silent,
    )
    .unwrap();
    assert_eq!(full.branch.stop, BranchStop::Reached);
    assert!(full.branch.points.len() > a.branch.points.len());
    assert_eq!(full.exit_code(), 0);
}

/// Invalid combinations are the library's errors, before any work.
#[test]
fn the_library_refuses_invalid_sweep_options() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/duffing.toml");
    let scene = Scene::load(&path).unwrap();
    let cases: Vec<(SweepSettings, &str)> = vec![
        (SweepSettings::to(f64::NAN), "--to must be a finite speed"),
        (
            SweepSettings {
                from: Some(-1.0),
                ..SweepSettings::to(2.0)
            },
            "--from must be a finite speed",
        ),
        (
            SweepSettings {
                max_step: 0.0,
                ..SweepSettings::to(2.0)
            },
            "--max-step must be finite and > 0",
        ),
        (
            SweepSettings {
                max_points: Some(0),
                ..SweepSettings::to(2.0)
            },
            "--max-points must be at least 1",
        ),
        (
            SweepSettings {
                all_branches: true,
                stability: false,
                ..SweepSettings::to(2.0)
            },
            "--all-branches needs the stability",
        ),
        (
            SweepSettings {
                output: Some("nothing".into()),
                ..SweepSettings::to(2.0)
            },
            "--output `nothing` is neither",
        ),
        (
            SweepSettings {
                dofs: Some("x,,x".into()),
                ..SweepSettings::to(2.0)
            },
            "--dofs has an empty name",
        ),
    ];
    for (settings, message) in cases {
        let e = sweep(&scene, &settings, &mut Silent).unwrap_err();
        assert!(e.to_string().contains(message), "{e}");
        assert_eq!(e.exit_code(), 2, "{e}");
    }
    // Start harmonics with automatic harmonics: refused as the solve refuses them (they were
    // fed into the automatic H, exit 1 after its solve, or ignored).
    let mut auto = Scene::load(&path).unwrap();
    auto.auto = Some(hbal::solve::AutoHarmonics::default());
    let n = auto.model.n_dofs() * (auto.basis.harmonics() + 1);
    let start = hbal::analysis::SweepStart {
        harmonics: vec![num_complex::Complex64::default(); n],
        omega: None,
        label: "previous.json".into(),
    };
    let settings = SweepSettings {
        start: Some(start),
        ..SweepSettings::to(2.0)
    };
    let e = sweep(&auto, &settings, &mut Silent).unwrap_err();
    assert!(e.to_string().contains("--start needs a fixed H"), "{e}");
    assert_eq!(e.exit_code(), 2);
}

/// The parameter sweep: the library's result is `hbal sweep --parameter --json`; a field that
/// changes the model's DOFs is bad input before any work; a cancelled sweep keeps its points.
#[test]
fn the_parameter_sweep_runs_in_the_library() {
    use hbal::analysis::{parameter_sweep, ParameterSweepSettings};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/duffing.toml");
    let file = path.display().to_string();
    let doc = Scene::parse_value(&std::fs::read_to_string(&path).unwrap(), &file).unwrap();
    let settings = ParameterSweepSettings {
        parameter: "loads[0].cos".into(),
        from: 0.02,
        to: 0.1,
        points: 6,
        stability: true,
        overrides: Default::default(),
        dofs: None,
        cancel: Cancel::default(),
    };
    let a = parameter_sweep(&doc, &file, &settings, &mut Silent).unwrap();
    assert_eq!(a.branch.points.len(), 6);
    assert_eq!(a.exit_code(), 0);
    let mut library: Value = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args(["sweep", "--json", "--parameter", "loads[0].cos"])
        .args(["--from", "0.02", "--to", "0.1", "--points", "6"])
        .arg(&path)
        .output()
        .unwrap();
    let mut cli: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(difference_without_times(&mut library, &mut cli), None);
    assert_eq!(cli["schema_version"], 1);
    // The response grows with the load.
    let m: Vec<f64> = a.branch.points.iter().map(|p| p.max_abs[0]).collect();
    assert!(m.windows(2).all(|w| w[1] > w[0]), "{m:?}");

    let dofs = ParameterSweepSettings {
        parameter: "dofs.count".into(),
        ..settings.clone()
    };
    let e = parameter_sweep(&doc, &file, &dofs, &mut Silent).unwrap_err();
    assert!(e.to_string().contains("changes the model's DOFs"), "{e}");
    assert_eq!(e.exit_code(), 2);
    let method = ParameterSweepSettings {
        overrides: hbal::scene::Overrides {
            method: Some("newton".into()),
            ..Default::default()
        },
        ..settings.clone()
    };
    let e = parameter_sweep(&doc, &file, &method, &mut Silent).unwrap_err();
    assert!(
        e.to_string().contains("--method applies to speed sweeps"),
        "{e}"
    );

    let cancel = Cancel::new();
    let mut observer = CancelAfter {
        fractions: Vec::new(),
        cancel: cancel.clone(),
    };
    let cancelled = ParameterSweepSettings { cancel, ..settings };
    let c = parameter_sweep(&doc, &file, &cancelled, &mut observer).unwrap();
    assert_eq!(c.branch.points.len(), 3);
    assert!(
        matches!(c.branch.stop, BranchStop::Cancelled { .. }),
        "{}",
        c.branch.stop
    );
    assert_eq!(c.exit_code(), 1);
}

/// The library example (`examples/analyses.rs`, built by `cargo test` beside the tests)
/// prints what `hbal solve --json` and `hbal sweep --json` print for the two-shaft scene.
#[test]
fn the_library_example_prints_what_the_cli_prints() {
    let bin = Path::new(env!("CARGO_BIN_EXE_hbal"));
    let example = bin.parent().unwrap().join("examples").join("analyses");
    if !example.exists() {
        // `cargo test --test integration` alone does not build the examples; `cargo test` does.
        eprintln!("skipped: {} not built", example.display());
        return;
    }
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/two_shaft_6000rpm.toml");
    let out = std::process::Command::new(&example)
        .arg(&scene)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2);
    let cli = |args: &[&str]| -> Value {
        let o = std::process::Command::new(bin)
            .args(args)
            .arg(&scene)
            .output()
            .unwrap();
        serde_json::from_slice(&o.stdout).unwrap()
    };
    for (line, args) in lines.iter().zip([
        vec!["solve", "--json"],
        vec!["sweep", "--json", "--to", "9000"],
    ]) {
        let mut mine: Value = serde_json::from_str(line).unwrap();
        let mut theirs = cli(&args);
        assert_eq!(
            difference_without_times(&mut mine, &mut theirs),
            None,
            "{args:?}"
        );
    }
}
