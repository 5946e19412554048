//! Loads that follow the speed (`SpeedLaw`: a power of Ω, a table over rpm): the load at each
//! speed of a sweep, `∂R/∂Ω` with them, scenes and their bad input.

use hbal::continuation::Continuation;
use hbal::force::CubicSpring;
use hbal::linear::Formulation;
use hbal::model::{SpeedLaw, Speeds};
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
use nalgebra::DMatrix;
use std::f64::consts::TAU;

const RPM: f64 = TAU / 60.0;

/// A table of amplitude and phase over 10..40 rpm.
fn table() -> SpeedLaw {
    SpeedLaw {
        exponent: None,
        rpm: Speeds::Table(vec![10.0, 20.0, 30.0, 40.0]),
        amplitude: vec![0.02, 0.05, 0.03, 0.04],
        phase: vec![0.0, 0.4, -0.2, 0.1],
        fundamental_order: 1.0,
    }
}

/// Two DOFs with a cubic spring: an unbalance ∝ Ω² on `a`, order 2 from a table on `b`, and
/// a static load ∝ Ω on `b`; or the same loads frozen at the speed `frozen` (rad/s).
fn model(frozen: Option<f64>) -> Model {
    let laws = [
        (0, 1, 0.01, 0.005, SpeedLaw::power(2.0, 15.0)),
        (1, 2, 1.0, 0.0, table()),
        (1, 0, 0.3, 0.0, SpeedLaw::power(1.0, 20.0)),
    ];
    let mut b = Model::builder(&["a", "b"])
        .mass(DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.5]))
        .damping(DMatrix::from_row_slice(2, 2, &[0.06, -0.02, -0.02, 0.05]))
        .stiffness(DMatrix::from_row_slice(2, 2, &[5.0, -2.0, -2.0, 3.0]))
        .element("duffing", &[("a", 1.0)], CubicSpring::new(0.0, 2.0));
    for (dof, order, c, s, law) in laws {
        let dof = ["a", "b"][dof];
        b = match frozen {
            None => b.load_over_speed(dof, order, c, s, law),
            Some(w) => {
                let z = num_complex::Complex64::new(c, s) * law.factor(w);
                b.load(dof, order, z.re, z.im)
            }
        };
    }
    b.build().unwrap()
}

/// The laws at their defining speeds: the power law's reference, the table's own entries
/// and the linear interpolation (amplitude and phase) between them.
#[test]
fn laws_give_their_values_at_the_defining_speeds() {
    let p = SpeedLaw::power(2.0, 15.0);
    assert!((p.factor(15.0 * RPM).re - 1.0).abs() < 1e-15);
    assert!((p.factor(30.0 * RPM).re - 4.0).abs() < 1e-14);
    assert!((p.derivative(30.0 * RPM).re - 2.0 * 4.0 / (30.0 * RPM)).abs() < 1e-12);
    let t = table();
    for (n, a, psi) in [(20.0, 0.05, 0.4), (30.0, 0.03, -0.2), (25.0, 0.04, 0.1)] {
        let z = t.factor(n * RPM);
        assert!((z.norm() - a).abs() < 1e-15, "{n} rpm: |T| = {}", z.norm());
        assert!(
            (z.arg() + psi).abs() < 1e-13,
            "{n} rpm: arg T = {}",
            z.arg()
        );
    }
    // The slope by central differences inside a segment.
    let (w, h) = (27.0 * RPM, 1e-6);
    let fd = (t.factor(w + h) - t.factor(w - h)) / (2.0 * h);
    assert!((fd - t.derivative(w)).norm() < 1e-7 * t.derivative(w).norm());
    // A scene's fundamental at order 1/2 of the reference shaft: Ω = Ω_ref / 2.
    let half = table().on_fundamental_order(0.5);
    assert_eq!(half.factor(10.0 * RPM), t.factor(20.0 * RPM));
}

/// `∂R/∂Ω` with loads that follow the speed, full and condensed, against central
/// differences of the residual in Ω.
#[test]
fn omega_derivative_includes_the_loads() {
    let model = model(None);
    for formulation in [Formulation::Full, Formulation::Condensed] {
        let omega = 22.5 * RPM;
        let basis = HarmonicBasis::new(omega, 5).unwrap();
        let mut hb = HarmonicBalance::with_formulation(&model, basis, formulation).unwrap();
        let m = hb.layout().len();
        let x: Vec<f64> = (0..m).map(|i| 0.05 * ((i as f64) * 0.7).sin()).collect();
        crate::common::assert_omega_derivative(&mut hb, &x, &format!("{formulation:?}"));
    }
}

/// A sweep with continuation carries the loads along: every point equals a solve of the same
/// model with its loads frozen at that point's speed.
#[test]
fn sweep_points_equal_solves_with_the_loads_of_their_speed() {
    let moving = model(None);
    let basis = HarmonicBasis::new(12.0 * RPM, 6).unwrap();
    let branch = Continuation::default()
        .run(&moving, basis, 38.0 * RPM, |_| {})
        .unwrap();
    assert!(branch.points.len() > 10, "{} points", branch.points.len());
    let last = branch.points.last().unwrap();
    assert!(
        (last.omega - 38.0 * RPM).abs() < 1e-9,
        "ends at {}",
        last.omega
    );
    for p in branch.points.iter().step_by(3) {
        let frozen = model(Some(p.omega));
        let hb = HarmonicBalance::new(&frozen, HarmonicBasis::new(p.omega, 6).unwrap()).unwrap();
        let sol = Newton::new()
            .with_tolerance(1e-13)
            .unwrap()
            .solve_from(&hb, &p.harmonics, &mut hb.workspace())
            .unwrap();
        let scale = p.harmonics.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for (a, b) in sol.harmonics().iter().zip(&p.harmonics) {
            assert!((a - b).norm() < 1e-8 * scale, "Ω {}: {a} vs {b}", p.omega);
        }
    }
}

/// Outside a table the analysis is refused, never extrapolated; inside it runs.
#[test]
fn a_speed_outside_the_table_is_refused() {
    let model = model(None);
    let err = HarmonicBalance::new(&model, HarmonicBasis::new(45.0 * RPM, 5).unwrap())
        .err()
        .unwrap();
    let msg = err.to_string();
    assert!(msg.contains("load on `b` order 2"), "{msg}");
    assert!(
        msg.contains("10 to 40 rpm") && msg.contains("needs 45 rpm"),
        "{msg}"
    );
    assert_eq!(err.exit_code(), 2);
    // A sweep of the nonlinear model reaches the table's last speed exactly (its predictor
    // may look past it), and a branch that leaves the table stops there with the table's
    // message, its points all inside.
    let basis = HarmonicBasis::new(30.0 * RPM, 5).unwrap();
    let to_end = Continuation::default()
        .run(&model, basis, 40.0 * RPM, |_| {})
        .unwrap();
    assert_eq!(to_end.stop, hbal::continuation::BranchStop::Reached);
    assert!((to_end.points.last().unwrap().omega - 40.0 * RPM).abs() < 1e-12);
    let beyond = Continuation::default()
        .run(&model, basis, 45.0 * RPM, |_| {})
        .unwrap();
    let hbal::continuation::BranchStop::Failed { reason, .. } = &beyond.stop else {
        panic!("{:?}", beyond.stop);
    };
    assert!(reason.contains("never extrapolated"), "{reason}");
    assert!(beyond
        .points
        .iter()
        .all(|p| p.omega <= 40.0 * RPM * (1.0 + 1e-12)));
    // The time integration and the Floquet analysis refuse a speed outside it too.
    let err = hbal::timesim::TimeSimulation::new()
        .run(&model, 41.0 * RPM)
        .unwrap_err();
    assert!(err.to_string().contains("never extrapolated"), "{err}");
}

/// A shaft line with an engine order from a table over speed (a half order: hbal runs on the
/// fundamental of order 1/2) and a propeller torque ∝ n².
const SCENE: &str = r#"
fundamental = { rpm = 1500 }
harmonics = { count = 8 }
loads = [
  { dof = "propeller", order = 2, cos = -40.0, speed = { exponent = 2, rpm = 1500 } },
  { dof = "flywheel", order = 1, speed = { rpm = [1000, 2000, 2500], amplitude = [10, 30, 20], phase = [0, 0.5, 1.0] } },
]
[engine]
dof = "crank"
cylinders = 1
orders = [
  { order = 0.5, amplitude = 5.0 },
  { order = 1.5, speed = { rpm = [1000, 2000, 2500], amplitude = [100, 300, 200], phase = [0.1, 0.2, 0.3] } },
]
[line]
disks = [
  { name = "crank", inertia = 0.4 },
  { name = "flywheel", inertia = 1.5 },
  { name = "propeller", inertia = 3.0, damping = 20.0 },
]
shafts = [
  { from = "crank", to = "flywheel", stiffness = 3e5, damping = 6.0 },
  { from = "flywheel", to = "propeller", stiffness = 8e4, damping = 3.0 },
]
"#;

/// The scene's loads at a speed are the table's entries and the power law's values there, in
/// rpm of the reference shaft whatever fundamental hbal chose.
#[test]
fn scene_loads_follow_the_reference_shaft_speed() {
    let scene = hbal::scene::Scene::from_str(SCENE, "line.toml").unwrap();
    assert_eq!(scene.fundamental_order, 0.5);
    let at = |dof: &str, k: usize, rpm: f64| {
        let i = scene.model.dof_index(dof).unwrap();
        let l = scene
            .model
            .loads()
            .iter()
            .find(|l| l.dof == i && l.order == k)
            .unwrap();
        let (c, s) = l.at(0.5 * rpm * RPM);
        num_complex::Complex64::new(c, s)
    };
    // Engine order 1.5 is harmonic 3: A e^{-iψ} at the table's speeds (one cylinder, φ_1 = 0).
    for (rpm, a, psi) in [
        (1000.0, 100.0, 0.1),
        (2000.0, 300.0, 0.2),
        (1500.0, 200.0, 0.15),
    ] {
        let z = at("crank", 3, rpm);
        assert!(
            (z.norm() - a).abs() < 1e-12 && (z.arg() + psi).abs() < 1e-14,
            "{rpm}: {z}"
        );
    }
    // A plain load's order counts harmonics of the fundamental; the propeller's ∝ n².
    let z = at("flywheel", 1, 2250.0);
    assert!(
        (z.norm() - 25.0).abs() < 1e-12 && (z.arg() + 0.75).abs() < 1e-14,
        "{z}"
    );
    assert!((at("propeller", 2, 3000.0).re + 160.0).abs() < 1e-10);
    // The constant order 0.5 stays.
    assert!((at("crank", 1, 2400.0).re - 5.0).abs() < 1e-15);
}

/// `hbal sweep` runs the run-up across the table; a range beyond it, a table that does not
/// increase, `cos` beside a table, an engine amplitude beside its table: exit 2, named.
#[test]
fn sweeps_within_the_table_run_and_bad_tables_are_refused() {
    let dir = crate::common::cli::temp_dir("speed-loads");
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_string_lossy().into_owned()
    };
    let good = write("good.toml", SCENE);
    let out = crate::common::hbal(&["sweep", &good, "--to", "2500", "--json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = crate::common::cli::json_of(&out);
    let points = json["branches"][0]["points"]
        .as_array()
        .or(json["points"].as_array());
    assert!(points.is_some_and(|p| p.len() > 5), "{json}");
    let beyond = crate::common::hbal(&["sweep", &good, "--to", "2600"]);
    let err = String::from_utf8_lossy(&beyond.stderr);
    assert_eq!(beyond.status.code(), Some(2), "{err}");
    assert!(
        err.contains("load on `crank` order 3") && err.contains("1000 to 2500 rpm"),
        "{err}"
    );
    assert!(err.contains("1500 to 2600 rpm"), "{err}");
    for (text, path, words) in [
        (
            SCENE.replace(
                "[1000, 2000, 2500], amplitude = [10, 30",
                "[1000, 2000, 1900], amplitude = [10, 30",
            ),
            "loads[1].speed.rpm",
            "strictly increasing",
        ),
        (
            SCENE.replace("order = 1, speed", "order = 1, cos = 3.0, speed"),
            "loads[1].cos",
            "leave `cos` and `sin` out",
        ),
        (
            SCENE.replace("order = 1.5, speed", "order = 1.5, amplitude = 3.0, speed"),
            "engine.orders[1].amplitude",
            "given by the table",
        ),
        (
            SCENE.replace("amplitude = [100, 300, 200]", "amplitude = [100, 300]"),
            "engine.orders[1].speed.amplitude",
            "one value per speed (3), got 2",
        ),
        (
            SCENE.replace("exponent = 2, rpm = 1500", "exponent = 2, rpm = 0"),
            "loads[0].speed.rpm",
            "> 0",
        ),
    ] {
        crate::common::cli::check_refuses(&dir, &text, path, words);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A scene written back (`write_scene`) keeps its loads' speed laws: the same loads at every
/// speed.
#[test]
fn written_scenes_keep_the_speed_laws() {
    use hbal::scene::export::{write_scene, SceneSettings};
    let scene = hbal::scene::Scene::from_str(SCENE, "line.toml").unwrap();
    let dir = crate::common::cli::temp_dir("speed-loads-export");
    let file = dir.join("line.toml");
    let mut settings = SceneSettings::new("line", "rpm", 1500.0, 8);
    settings.order = 0.5;
    write_scene(&scene.model, &settings, &file).unwrap();
    let back = hbal::scene::Scene::load(&file).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(back.model.loads().len(), scene.model.loads().len());
    for rpm in [1000.0, 1234.5, 2000.0, 2500.0] {
        let w = 0.5 * rpm * RPM;
        for (a, b) in scene.model.loads().iter().zip(back.model.loads()) {
            let ((c1, s1), (c2, s2)) = (a.at(w), b.at(w));
            let scale = c1.hypot(s1).max(1.0);
            assert!((c1 - c2).abs() < 1e-12 * scale && (s1 - s2).abs() < 1e-12 * scale);
        }
    }
}
