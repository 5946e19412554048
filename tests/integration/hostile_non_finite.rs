//! The hostile inputs of issue 13 that produce non-finite values: stopped where they arise,
//! named, never printed as `null`, NaN or inf (forces, library errors, parameter sweeps).

use crate::common::hostile::{judge_document, run_limited, write, Document};
use crate::hostile_input::{edited, example, expect, temp_dir};
use hbal::scene::Scene;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};

/// A force that overflows is a termination that names the element and the angle, said once;
/// the JSON holds the last finite iterate and no `null`, and the exit code is 1.
#[test]
fn non_finite_forces_stop_with_where_not_nan() {
    let scene = edited(
        "polynomial_spring.toml",
        "coefficients = [1.0, 0.5, 0.3]",
        "coefficients = [1.0, 0.5, 0.3, 1e90]",
    )
    .replace("order = 1, cos = 0.3", "order = 1, cos = 1e10");
    let run = expect(
        "overflow.toml",
        &scene,
        &["solve", "--json", "{}", "--method", "anderson"],
        1,
        "",
    );
    let doc: serde_json::Value = serde_json::from_str(&run.stdout).expect("one JSON object");
    assert_eq!(doc["converged"], false);
    let termination = doc["termination"].as_str().expect("termination");
    assert!(
        termination.starts_with("non-finite value in force of element `spring` at θ = "),
        "{termination}"
    );
    assert!(
        !termination.contains("non-finite value in non-finite"),
        "{termination}"
    );
    let _ = std::fs::remove_dir_all(temp_dir());
}

/// A start without a finite residual is an error that names the harmonic and DOF (there is no
/// iterate to report), and a dynamic stiffness that overflows is not called a resonance.
#[test]
fn library_non_finite_errors_name_the_place() {
    let text = example("duffing.toml").replace("cos = 0.1", "cos = 1e100");
    let scene = Scene::from_str(&text, "duffing.toml").expect("in range");
    let hb = HarmonicBalance::new(&scene.model, scene.basis).expect("discretised");
    let err = Newton::new().solve(&hb, &mut hb.workspace()).unwrap_err();
    let message = err.to_string();
    assert!(
        message.starts_with("non-finite value in the norm of the residual (its largest entry, ")
            && message.ends_with("at harmonic 1 (cos) of `x`, overflows when squared)"),
        "{message}"
    );
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1e308])
        .stiffness(hbal::nalgebra::DMatrix::from_element(1, 1, 1.0))
        .load("x", 1, 1.0, 0.0)
        .build()
        .expect("the library takes any finite mass");
    let err = HarmonicBalance::new(&model, HarmonicBasis::new(2.0, 2).unwrap()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "non-finite value in the dynamic stiffness at harmonic 1 (2e0 rad/s): the mass, damping \
         or stiffness times the frequency (squared) is out of range"
    );
    // A speed whose period is infinite is refused where the basis is made.
    let err = HarmonicBasis::new(1e-320, 4).unwrap_err().to_string();
    assert!(
        err.contains("parameter `omega` must be finite and in [1e-100, 1e100] rad/s"),
        "{err}"
    );
}

/// A parameter sweep that meets an undamped resonance keeps its points and exits 1; an
/// unusable `--out` is refused before the sweep (exit 2). (A DOF name that cannot be part of a
/// file name is refused: tests/integration/report.rs.)
#[test]
fn parameter_sweep_failures_are_honest() {
    let undamped = "dofs = [\"x1\"]\nmass = [[1.0]]\nstiffness = [[1.0]]\n\
                    fundamental = { rad_s = 0.6 }\nharmonics = { count = 3 }\n\
                    loads = [{ dof = \"x1\", order = 1, cos = 0.1 }]\n[[elements]]\n\
                    name = \"s\"\ntype = \"cubic_spring\"\nconnects = { \"x1\" = 1.0 }\n\
                    k = 0.0\nalpha = 0.1\n";
    let dir = temp_dir();
    let out = dir.join("out");
    let out = out.to_str().expect("utf-8");
    let sweep = [
        "sweep",
        "{}",
        "--parameter",
        "fundamental.rad_s",
        "--from",
        "0.6",
        "--to",
        "1.5",
        "--points",
        "10",
        "--no-stability",
        "--out",
        out,
    ];
    let run = expect(
        "undamped.toml",
        undamped,
        &sweep,
        1,
        "failed at parameter 1: dynamic stiffness is singular at harmonic 1",
    );
    assert!(
        run.stdout.contains("4 values of fundamental.rad_s"),
        "{}",
        run.stdout
    );
    assert!(dir.join("out/parameter_response_x1.svg").is_file());
    let blocked = dir.join("undamped.toml");
    let blocked = format!("{}/sub", blocked.display());
    let mut args = sweep;
    args[12] = &blocked;
    let run = expect(
        "undamped.toml",
        undamped,
        &args,
        2,
        "cannot create the directory",
    );
    assert!(run.stdout.is_empty(), "{}", run.stdout);
    let _ = std::fs::remove_dir_all(temp_dir());
}

/// Found by the hostile property test on CI: the gear pair without mean load never closes its
/// contact in the time-domain reference (mesh force identically 0) while the unconverged
/// Newton iterate does. The worst quantity's error is measured against the iterate's own
/// range (between 1/2 and 1), not printed as `null` (infinity).
#[test]
fn a_reference_quantity_without_range_has_a_finite_error() {
    let scene = edited(
        "gear_backlash.toml",
        "order = 0, cos = 0.1",
        "order = 0, cos = 0.0",
    );
    let file = write(&temp_dir(), "no_mean_load.toml", &scene);
    let run = run_limited(&["compare", "--json", &file, "--method", "newton"]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.stderr.contains("no method converged"), "{}", run.stderr);
    judge_document(&run, Document::Compare).unwrap_or_else(|(b, w)| panic!("{b:?}: {w}"));
    assert!(!run.stdout.contains("null"), "{}", run.stdout);
    let doc: serde_json::Value = serde_json::from_str(&run.stdout).expect("one JSON object");
    let worst = &doc["methods"][0]["worst_quantity_vs_time_domain"];
    let error = worst["error"].as_f64().expect("a finite error");
    assert!((0.5..=1.0).contains(&error), "{worst}");
    let _ = std::fs::remove_dir_all(temp_dir());
}

/// Found by the hostile property test: the clutch damper with its spring to ground only, the
/// spline twice as stiff and the gearbox almost free. The friction washers chatter between
/// stick and slip in the stability's shooting, which restarted its integrator without end (a
/// solve ran for hours); now the chattering is a named stability failure within a second, the
/// solve itself stands, exit code 1.
#[test]
fn a_chattering_slider_stops_the_shooting_with_its_reason() {
    let scene = edited(
        "clutch_damper_hysteresis.toml",
        "[0.0, 20000.0, -20000.0], [0.0, -20000.0, 20800.0]",
        "[0.0, 40000.0, -20000.0], [0.0, -20000.0, 0.0208]",
    )
    .replace(
        "connects = { flywheel = 1.0, hub = -1.0 }   # u = damper twist, rad",
        "connects = { hub = -1.0 }",
    );
    let file = write(&temp_dir(), "chatter.toml", &scene);
    let run = run_limited(&["solve", "--json", &file]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.seconds < 30.0, "{} s", run.seconds);
    assert!(
        run.stderr
            .contains("switched between holding and moving 10000 times"),
        "{}",
        run.stderr
    );
    judge_document(&run, Document::Solve).unwrap_or_else(|(b, w)| panic!("{b:?}: {w}"));
    let doc: serde_json::Value = serde_json::from_str(&run.stdout).expect("one JSON object");
    assert_eq!(doc["converged"], true, "the solve itself stands");
    let _ = std::fs::remove_dir_all(temp_dir());
}

/// The scenes on several base frequencies print `caps_stopped: null` (the caps met their
/// tolerance) and, in a sweep, `bases[].hz: null`: documented nulls, not non-finite numbers
/// (the hostile property test met them on the planetary set).
#[test]
fn torus_documents_have_only_documented_nulls() {
    for name in ["planetary_set.toml", "two_stage_train_torus.toml"] {
        let file = write(&temp_dir(), name, &example(name));
        let run = run_limited(&["solve", "--json", &file]);
        assert_eq!(run.code, Some(0), "{name}: {}", run.stderr);
        assert!(run.stdout.contains("\"caps_stopped\":null"), "{name}");
        judge_document(&run, Document::Solve).unwrap_or_else(|(b, w)| panic!("{name}: {b:?}: {w}"));
    }
    let file = write(
        &temp_dir(),
        "torus.toml",
        &example("two_stage_train_torus.toml"),
    );
    let args = [
        "sweep", "--json", &file, "--from", "1000", "--to", "1100", "--points", "2",
    ];
    let run = run_limited(&args);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    judge_document(&run, Document::Sweep).unwrap_or_else(|(b, w)| panic!("sweep: {b:?}: {w}"));
    let _ = std::fs::remove_dir_all(temp_dir());
}
