//! Scenes on several base frequencies: hbal chooses the torus where one fundamental cannot
//! hold the meshes, the scene's torus equals the library's, d = 1 equals the one-frequency
//! engine, automatic caps reach their tolerance, and bad input names its field.

use hbal::analysis::{solve, torus_solve, SolveSettings, TorusSolveSettings};
use hbal::catalog::TwoStageTrain;
use hbal::scene::{Overrides, Scene};
use hbal::torus::{NewtonKrylov, TorusBalance};

fn scene_path(name: &str) -> String {
    format!("{}/examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn text(name: &str) -> String {
    std::fs::read_to_string(scene_path(name)).unwrap()
}

/// The scene `two_stage_train_torus.toml` is the catalog's `TwoStageTrain`: the same
/// transmission-error lines of both stages at 3000 rpm (the scene writes 23/67 as a decimal,
/// so not to the last bit).
#[test]
fn two_stage_scene_equals_the_catalog_train() {
    let scene = Scene::load(std::path::Path::new(&scene_path(
        "two_stage_train_torus.toml",
    )))
    .unwrap();
    let plan = scene.torus.as_ref().expect("on the torus");
    assert_eq!(plan.bases.names(), ["engine", "stage1", "stage2"]);
    assert_eq!(plan.caps, [8, 4, 4]);
    assert_eq!(plan.samples, [32, 16, 16]);
    let a = torus_solve(&scene, &TorusSolveSettings::default()).unwrap();
    assert!(a.converged, "{}", a.relative_residual);
    assert_eq!(a.lines, 689);
    assert_eq!(a.exit_code(), 0);

    let model = TwoStageTrain::default().model().unwrap();
    let hb = TorusBalance::new(
        TwoStageTrain::bind(&model).unwrap(),
        hbal::torus::IndexSet::new(
            &TwoStageTrain::bases().unwrap(),
            &[8, 4, 4],
            hbal::torus::Truncation::Box,
        )
        .unwrap(),
        &[32, 16, 16],
        3000.0 * std::f64::consts::TAU / 60.0,
    )
    .unwrap();
    let reference = NewtonKrylov::default().solve(&hb, None).unwrap();
    assert_eq!(reference.indices, a.solution.indices);
    let weights = |e: usize| model.elements()[e].weights().to_vec();
    for (e, name) in [(0, "stage1"), (1, "stage2")] {
        let te = &a.elements.iter().find(|s| s.name == name).unwrap();
        let w = weights(e);
        let n = reference.n_dofs();
        let line = |k: &[i32]| {
            let j = reference.indices.iter().position(|i| i == k).unwrap();
            w.iter()
                .fold(hbal::num_complex::Complex64::default(), |acc, &(i, c)| {
                    let (re, im) = reference.harmonics[j * n + i];
                    acc + hbal::num_complex::Complex64::new(re, im) * c
                })
        };
        let scale = te.rms;
        assert!(scale > 1e-7, "{name}: {scale}");
        for l in &te.lines {
            let want = line(&l.k).norm();
            assert!(
                (l.amplitude - want).abs() < 1e-8 * scale,
                "{name} {}: {} vs {want}",
                l.label,
                l.amplitude
            );
        }
    }
    // Every stage's strongest TE line is a harmonic of its own mesh (stage 1's third, 3450 Hz,
    // near the stage-2 mesh mode), labelled so, at the order of the speed it has.
    let top = |e: usize| &a.elements[e].lines[0];
    assert_eq!(
        (top(0).label.as_str(), top(0).k.as_slice()),
        ("3 stage1", &[0, 3, 0][..])
    );
    assert!((top(0).order - 69.0).abs() < 1e-12 && (top(0).hz - 3450.0).abs() < 1e-9);
    assert_eq!(top(1).k[0..1], [0]);
    assert_eq!(top(1).k[1], 0);
}

/// `bases = "auto"` keeps one fundamental where it holds the meshes (the car drivetrain at
/// H = 1024 holds mesh 1 at harmonic 851) and takes the torus where it cannot (H = 512),
/// saying why; the one-frequency analyses refuse a torus scene with the reason.
#[test]
fn auto_bases_choose_the_torus_only_where_one_fundamental_cannot_hold_the_meshes() {
    let car = text("car_drivetrain_two_stage.toml");
    let one = Scene::from_str(&car, "car.toml").unwrap();
    assert!(one.torus.is_none());
    let short = car.replace("count = 1024", "count = 512");
    let torus = Scene::from_str(&short, "car.toml").unwrap();
    let plan = torus.torus.as_ref().expect("torus");
    assert!(
        plan.why.contains("`stage1` meshes at harmonic 851"),
        "{}",
        plan.why
    );
    assert_eq!(plan.bases.names(), ["engine", "stage1", "stage2"]);
    assert_eq!(plan.bases.ratios()[0], 1.0); // engine orders 2, 4, 6 and the crank's 1
    let err = solve(&torus, &SolveSettings::default()).unwrap_err();
    assert!(
        err.to_string().contains("several base frequencies"),
        "{err}"
    );
    assert_eq!(err.exit_code(), 2);
    let forced = car.replace("count = 1024", "count = 1024, bases = \"torus\"");
    assert!(Scene::from_str(&forced, "car.toml")
        .unwrap()
        .torus
        .is_some());
}

/// One base (a Duffing scene forced onto the torus) is the one-frequency basis: the same
/// harmonics as the one-frequency engine.
#[test]
fn one_base_equals_the_one_frequency_engine() {
    let duffing = text("duffing.toml");
    let one = Scene::from_str(&duffing, "duffing.toml").unwrap();
    let h = one.basis.harmonics();
    let torus_text = duffing.replace(
        &format!("harmonics = {{ count = {h} }}"),
        &format!("harmonics = {{ bases = \"torus\", caps = {{ shaft = {h} }}, grid = {{ shaft = {} }} }}", one.basis.samples()),
    );
    assert_ne!(torus_text, duffing, "the scene's harmonics line changed");
    let torus = Scene::from_str(&torus_text, "duffing.toml").unwrap();
    let t = torus_solve(&torus, &TorusSolveSettings::default()).unwrap();
    let s = solve(&one, &SolveSettings::default()).unwrap();
    assert!(t.converged && s.solution.is_converged());
    let q = |k| s.solution.harmonic(0, k);
    let scale: f64 = (1..=h).map(|k| q(k).norm()).fold(0.0, f64::max);
    for k in 1..=h {
        let j = t
            .solution
            .indices
            .iter()
            .position(|i| i[0] == k as i32)
            .unwrap();
        let (re, im) = t.solution.harmonics[j];
        let want = q(k);
        assert!(
            (hbal::num_complex::Complex64::new(re, im) - want).norm() < 1e-9 * scale,
            "harmonic {k}: {re} {im} vs {want}"
        );
    }
}

/// The torus example scene with automatic caps to `tolerance`.
fn auto_caps_scene(tolerance: &str) -> Scene {
    let base = text("two_stage_train_torus.toml");
    let auto = base.replace(
        "caps = { engine = 8, stage1 = 4, stage2 = 4 } }",
        &format!("caps = {{ engine = 8, stage1 = 4, stage2 = 4 }}, auto = true, tolerance = {tolerance} }}"),
    );
    assert_ne!(auto, base);
    Scene::from_str(&auto, "train.toml").unwrap()
}

/// Automatic caps raise the caps of the bases whose estimate is above the tolerance, and stop
/// below it.
#[test]
fn automatic_caps_reach_the_tolerance() {
    let scene = auto_caps_scene("2e-2");
    let a = torus_solve(&scene, &TorusSolveSettings::default()).unwrap();
    assert!(a.caps_stopped.is_none(), "{:?}", a.caps_stopped);
    assert!(a.levels.len() >= 2, "{:?}", a.levels);
    // At the first caps, stage 2's estimate (4e-2) is above 2e-2; only its cap grows.
    let first = &a.levels[0];
    assert!(first.estimates[2].unwrap() > 2e-2, "{:?}", first.estimates);
    assert_eq!(a.bases[0].cap, 8);
    assert!(a.bases[2].cap > 4);
    for b in &a.bases {
        assert!(b.estimate.unwrap() <= 2e-2, "{b:?}");
    }
}

fn scene_error(text: &str) -> String {
    Scene::from_str(text, "bad.toml").unwrap_err().to_string()
}

#[test]
fn bad_torus_input_names_the_field() {
    let base = text("two_stage_train_torus.toml");
    let caps = "caps = { engine = 8, stage1 = 4, stage2 = 4 }";
    let cases = [
        (
            base.replace(caps, "caps = { engine = 8, stage3 = 4 }"),
            "harmonics.caps.stage3: no base `stage3`",
        ),
        (
            base.replace(caps, &format!("{caps}, grid = {{ stage1 = 8 }}")),
            "harmonics.grid.stage1: must be at least 2 × cap + 1 = 9",
        ),
        (
            base.replace(caps, "caps = { engine = 4000, stage1 = 4000 }"),
            "harmonics.caps",
        ),
        (
            base.replace(caps, &format!("{caps}, samples = 64")),
            "harmonics.samples: applies to one fundamental",
        ),
        (
            base.replace(caps, &format!("{caps}, tolerance = 1e-3")),
            "harmonics.tolerance: only applies with `auto = true`",
        ),
        (
            base.replace("bases = \"torus\"", "bases = \"several\""),
            "unknown variant `several`",
        ),
        (
            base.replace("teeth = 19\n", "teeth = 19\nbase = \"engine\"\n"),
            "elements[1].base: a gear stage or planetary set follows its own mesh",
        ),
        (
            base.replace(caps, &format!("{caps}, total = 3")),
            "harmonics.total: must be at least 4 for the load on `crank` at order 4 of base `engine`",
        ),
        (
            base.replace(caps, "caps = { engine = 6, stage1 = 4, stage2 = 4 }"),
            "harmonics.caps.engine: must be at least 8 for the load on `crank` at order 8",
        ),
        (
            base.replace("name = \"stage2\"", "name = \"stage1\""),
            "`stage1` is also the name of the base of another gear stage",
        ),
    ];
    for (scene, want) in cases {
        let err = scene_error(&scene);
        assert!(err.contains(want), "{want}: {err}");
    }
    // An element's `base` must name a base; on one fundamental it has no meaning.
    let duffing = text("duffing.toml");
    let on = duffing.replace(
        "type = \"cubic_spring\"",
        "type = \"cubic_spring\"\nbase = \"mesh\"",
    );
    assert_ne!(on, duffing);
    let torus = on.replace("harmonics = {", "harmonics = { bases = \"torus\",");
    assert!(
        scene_error(&torus).contains("elements[0].base: no base `mesh` (the bases are: shaft)"),
        "{}",
        scene_error(&torus)
    );
    assert!(
        scene_error(&on).contains("elements[0].base: binds the element to a base of the torus"),
        "{}",
        scene_error(&on)
    );
    // `count` on the torus is the first base's cap (the harmonics of one fundamental it covers).
    let counted = duffing.replace("harmonics = {", "harmonics = { bases = \"torus\",");
    let plan = Scene::from_str(&counted, "duffing.toml")
        .unwrap()
        .torus
        .unwrap();
    assert_eq!(plan.caps, [7]);
    // Overrides of one fundamental are refused on the torus; the tolerance applies.
    let mut scene = Scene::load(std::path::Path::new(&scene_path(
        "two_stage_train_torus.toml",
    )))
    .unwrap();
    let err = Overrides {
        method: Some("newton".into()),
        ..Default::default()
    }
    .apply(&mut scene)
    .unwrap_err();
    assert!(
        err.to_string().contains("--method") && err.to_string().contains("harmonics.caps"),
        "{err}"
    );
    Overrides {
        tolerance: Some(1e-6),
        ..Default::default()
    }
    .apply(&mut scene)
    .unwrap();
    assert_eq!(scene.torus.as_ref().unwrap().tolerance, 1e-6);
    let err = torus_solve(&scene, &TorusSolveSettings { speed: Some(-5.0) }).unwrap_err();
    assert!(err.to_string().contains("speed"), "{err}");
}

/// Automatic caps over a run-up: where a point of the sweep still has an estimate above the
/// tolerance (mesh 1 near 1830 rpm with the caps both ends need), the caps that point needs are
/// found and the sweep runs again, until every converged point is within the tolerance
/// (release: 40 points 1000 → 6000 rpm take about 11 s).
#[test]
#[ignore = "release: about 11 s (CI runs it)"]
fn automatic_caps_in_a_run_up_hold_the_tolerance_at_every_point() {
    struct Stages(Vec<String>);
    impl hbal::analysis::Observer for Stages {
        fn stage(&mut self, what: &str) {
            self.0.push(what.to_string());
        }
    }
    let scene = auto_caps_scene("5e-2");
    let settings = hbal::analysis::TorusSweepSettings {
        from: Some(1000.0),
        to: 6000.0,
        points: 40,
    };
    let mut stages = Stages(Vec::new());
    let a = hbal::analysis::torus_sweep(&scene, &settings, &mut stages).unwrap();
    assert!(
        stages.0.iter().any(|s| s.contains("raising the caps")),
        "{:?}",
        stages.0
    );
    assert!(a.caps_stopped.is_none(), "{:?}", a.caps_stopped);
    for p in a.points.iter().filter(|p| p.converged) {
        for e in &p.estimates {
            assert!(e.unwrap() <= 5e-2, "{} rpm: {:?}", p.speed, p.estimates);
        }
    }
}

/// The drivetrain's 200-point run-up 1000 → 6000 rpm (caps 8/4/4): with the contact edges
/// corrected along each law's axis, every point converges but where the branch ends near
/// 2836 rpm (arclength stops there; docs/torus.md), which is marked. Sampled plainly, the
/// edges left 7 points unconverged (2834–2960 and 4769 rpm).
#[test]
#[ignore = "release: about 7 s (CI runs it)"]
fn drivetrain_run_up_converges_but_where_the_branch_ends() {
    let scene = Scene::from_str(&text("two_stage_train_torus.toml"), "train.toml").unwrap();
    let settings = hbal::analysis::TorusSweepSettings {
        from: Some(1000.0),
        to: 6000.0,
        points: 200,
    };
    let a = hbal::analysis::torus_sweep(&scene, &settings, &mut hbal::analysis::Silent).unwrap();
    assert_eq!(a.points.len(), 200);
    let failed: Vec<f64> = a
        .points
        .iter()
        .filter(|p| !p.converged)
        .map(|p| p.speed)
        .collect();
    assert!(
        failed.len() <= 2 && failed.iter().all(|s| (2830.0..2890.0).contains(s)),
        "not converged at {failed:?} rpm"
    );
}
