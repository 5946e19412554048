//! Engine excitation per order and cylinder: the loads equal the per-cylinder torques
//! `T_c(φ) = T̄ + Σ_o A_o cos(o (φ - φ_c) + ψ_o)` summed directly in time, the firing order
//! cancels the orders it should, the fundamental is chosen so that half orders are harmonics,
//! and bad tables are refused naming the field.

use crate::common;

use hbal::model::{Cylinders, EngineExcitation, EngineOrder};
use hbal::scene::Scene;
use std::f64::consts::PI;

fn four_cylinder(cylinders: Cylinders, dof: Option<&str>) -> EngineExcitation {
    EngineExcitation {
        dof: dof.map(str::to_string),
        cylinders,
        strokes: 4,
        firing_order: Some(vec![1, 3, 4, 2]),
        firing_angles: None,
        mean_torque: 20.0,
        orders: [
            (0.5, 30.0, 0.3),
            (1.0, 45.0, -0.2),
            (1.5, 25.0, 1.0),
            (2.0, 60.0, 0.1),
        ]
        .iter()
        .map(|&(order, amplitude, phase)| EngineOrder::new(order, amplitude, phase))
        .collect(),
    }
}

/// The torque on `dof` at crank angle φ from the loads (harmonic k of a fundamental of order
/// `f`: `cos · cos(k f φ) + sin · sin(k f φ)`).
fn from_loads(loads: &[hbal::model::engine::EngineLoad], dof: &str, f: f64, phi: f64) -> f64 {
    loads
        .iter()
        .filter(|l| l.0 == dof)
        .map(|&(_, k, c, s, _)| {
            let a = k as f64 * f * phi;
            c * a.cos() + s * a.sin()
        })
        .sum()
}

/// The per-cylinder formula, written out: cylinder `c` fires at `position(c) · 4π/n`.
fn direct(e: &EngineExcitation, cylinder: usize, phi: f64) -> f64 {
    let position = e
        .firing_order
        .as_ref()
        .unwrap()
        .iter()
        .position(|&c| c == cylinder)
        .unwrap();
    let phi_c = position as f64 * 4.0 * PI / e.count() as f64;
    e.mean_torque
        + e.orders
            .iter()
            .map(|o| o.amplitude * (o.order * (phi - phi_c) + o.phase).cos())
            .sum::<f64>()
}

#[test]
fn loads_equal_the_cylinder_torques_in_time() {
    let dofs: Vec<String> = (1..=4).map(|c| format!("crank.{c}")).collect();
    let e = four_cylinder(Cylinders::Dofs(dofs.clone()), None);
    e.validate("engine").unwrap();
    assert_eq!(e.fundamental_order(), Some(0.5));
    let loads = e.loads(0.5).unwrap();
    for (c, dof) in dofs.iter().enumerate() {
        for j in 0..37 {
            let phi = 4.0 * PI * j as f64 / 37.0 + 0.1;
            let (a, b) = (from_loads(&loads, dof, 0.5, phi), direct(&e, c + 1, phi));
            assert!(
                (a - b).abs() < 1e-12 * 200.0,
                "cylinder {}: {a} vs {b}",
                c + 1
            );
        }
    }
    // A fundamental of order 0.25 holds the same orders at twice the harmonic index.
    let quarter = e.loads(0.25).unwrap();
    for j in 0..11 {
        let phi = 0.7 * j as f64;
        let (a, b) = (
            from_loads(&quarter, "crank.3", 0.25, phi),
            direct(&e, 3, phi),
        );
        assert!((a - b).abs() < 1e-11, "{a} vs {b}");
    }
}

/// On one crank DOF a four-cylinder four-stroke engine keeps only the mean and the orders
/// 2, 4, ...: orders 0.5, 1, 1.5 cancel over the firing order; order 2 adds up in phase.
#[test]
fn firing_order_cancels_the_lower_orders_on_one_dof() {
    let e = four_cylinder(Cylinders::Count(4), Some("crank"));
    let loads = e.loads(0.5).unwrap();
    let sum = |k: usize| {
        loads
            .iter()
            .filter(|l| l.1 == k)
            .fold((0.0, 0.0), |a, l| (a.0 + l.2, a.1 + l.3))
    };
    assert!((sum(0).0 - 80.0).abs() < 1e-12);
    for k in [1, 2, 3] {
        let (c, s) = sum(k);
        assert!(
            c.abs() < 1e-12 && s.abs() < 1e-12,
            "order {}: {c} {s}",
            k as f64 / 2.0
        );
    }
    let (c, s) = sum(4);
    assert!((c - 4.0 * 60.0 * 0.1f64.cos()).abs() < 1e-12, "{c}");
    assert!((s + 4.0 * 60.0 * 0.1f64.sin()).abs() < 1e-12, "{s}");
}

/// A two-stroke engine fires every 2π/n: a three-cylinder one keeps orders 3, 6, ...
#[test]
fn two_stroke_firing_interval() {
    let e = EngineExcitation {
        dof: Some("crank".into()),
        cylinders: Cylinders::Count(3),
        strokes: 2,
        firing_order: None,
        firing_angles: None,
        mean_torque: 0.0,
        orders: (1..=3)
            .map(|o| EngineOrder::new(o as f64, 10.0, 0.0))
            .collect(),
    };
    assert_eq!(e.fundamental_order(), Some(1.0));
    let angles = e.firing_angles();
    assert!(
        (angles[1] - 2.0 * PI / 3.0).abs() < 1e-15 && (angles[2] - 4.0 * PI / 3.0).abs() < 1e-15
    );
    let loads = e.loads(1.0).unwrap();
    let total = |k: usize| -> f64 {
        let (c, s) = loads
            .iter()
            .filter(|l| l.1 == k)
            .fold((0.0, 0.0), |a, l| (a.0 + l.2, a.1 + l.3));
        c.hypot(s)
    };
    assert!(total(1) < 1e-12 && total(2) < 1e-12);
    assert!((total(3) - 30.0).abs() < 1e-12);
}

const SCENE: &str = r#"
dofs = ["engine", "flywheel"]
mass = [[0.15, 0.0], [0.0, 0.3]]
stiffness = [[5e4, -5e4], [-5e4, 5.1e4]]
damping = [[5.0, -5.0], [-5.0, 6.0]]
fundamental = { rpm = 3000 }
harmonics = { count = 8 }

[engine]
dof = "engine"
cylinders = 4
firing_order = [1, 3, 4, 2]
mean_torque = 25.0
orders = [{ order = 0.5, amplitude = 10.0 }, { order = 2.0, amplitude = 60.0 }]
"#;

/// The scene chooses the fundamental of order 0.5 (half the engine speed) for the half order;
/// order 2 is harmonic 4 and carries 4 x 60 N m.
#[test]
fn scene_chooses_a_fundamental_that_holds_half_orders() {
    let s = Scene::from_str(SCENE, "engine.toml").unwrap();
    assert!((s.basis.omega() - 0.5 * 3000.0 * 2.0 * PI / 60.0).abs() < 1e-9);
    assert!(s.notes.is_empty());
    // A `loads` entry of order >= 1 now counts half orders: the scene says so.
    let with_load = SCENE.replace(
        "harmonics = { count = 8 }",
        "harmonics = { count = 8 }\nloads = [{ dof = \"flywheel\", order = 2, cos = 1.0 }]",
    );
    let noted = Scene::from_str(&with_load, "engine.toml").unwrap();
    assert_eq!(noted.notes.len(), 1);
    assert!(
        noted.notes[0].contains("shaft order 1"),
        "{}",
        noted.notes[0]
    );
    let loads = s.model.loads();
    let order2: f64 = loads.iter().filter(|l| l.order == 4).map(|l| l.cos).sum();
    assert!((order2 - 240.0).abs() < 1e-12, "{order2}");
    let mean: f64 = loads.iter().filter(|l| l.order == 0).map(|l| l.cos).sum();
    assert!((mean - 100.0).abs() < 1e-12);
    // With `fundamental.order = 1` the half order is refused, and the message says what works.
    let err = Scene::from_str(
        &SCENE.replace("{ rpm = 3000 }", "{ rpm = 3000, order = 1 }"),
        "e.toml",
    )
    .unwrap_err();
    assert_eq!(err.path.as_deref(), Some("engine.orders[0].order"), "{err}");
    assert!(
        err.to_string().contains("`fundamental.order = 0.5`"),
        "{err}"
    );
}

#[test]
fn bad_engine_tables_name_the_field() {
    let cases = [
        (
            "firing_order = [1, 3, 4, 2]",
            "firing_order = [1, 3, 3, 2]",
            "engine",
            "`firing_order` must list each of the 4 cylinders",
        ),
        (
            "firing_order = [1, 3, 4, 2]",
            "firing_order = [1, 3, 2]",
            "engine",
            "`firing_order` must list each of the 4 cylinders",
        ),
        (
            "cylinders = 4",
            "cylinders = 0",
            "engine",
            "at least one cylinder",
        ),
        (
            "dof = \"engine\"",
            "dof = \"crank\"",
            "engine.dof",
            "unknown DOF `crank`",
        ),
        ("dof = \"engine\"\n", "", "engine", "`dof` is missing"),
        (
            "mean_torque = 25.0",
            "mean_torque = 25.0\nstrokes = 3",
            "engine.strokes",
            "2 or 4",
        ),
        (
            "{ order = 0.5, amplitude = 10.0 }",
            "{ order = -0.5, amplitude = 10.0 }",
            "engine.orders[0].order",
            "> 0",
        ),
        (
            "{ order = 0.5, amplitude = 10.0 }",
            "{ order = 0.5, amplitude = -10.0 }",
            "engine.orders[0].amplitude",
            ">= 0",
        ),
        (
            "{ order = 0.5, amplitude = 10.0 }",
            "{ order = 0.5, amplitude = 10.0, phse = 1.0 }",
            "engine.orders[0].phse",
            "unknown field",
        ),
        (
            "firing_order = [1, 3, 4, 2]",
            "firing_order = [1, 3, 4, 2]\nfiring_angles = [0.0, 1.0, 2.0, 3.0]",
            "engine",
            "exclude each other",
        ),
    ];
    for (from, to, path, what) in cases {
        let text = SCENE.replace(from, to);
        assert_ne!(text, SCENE, "{from}");
        let err = Scene::from_str(&text, "bad.toml").unwrap_err();
        assert_eq!(err.path.as_deref(), Some(path), "{to}: {err}");
        assert!(err.to_string().contains(what), "{to}: {err}");
    }
    let dir = std::env::temp_dir().join(format!("hbal-engine-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("bad.toml");
    std::fs::write(&p, SCENE.replace("[1, 3, 4, 2]", "[1, 2, 3]")).unwrap();
    let out = common::hbal(&["check", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("firing_order"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A gear stage whose mesh order is a half order of the reference (21 teeth at half the crank
/// speed: 10.5) is a harmonic of the automatic fundamental of order 0.5: 21 mesh cycles per
/// period.
#[test]
fn gear_stage_half_mesh_orders_set_the_fundamental() {
    let text = format!(
        "{SCENE}
[[elements]]
name = \"stage\"
type = \"gear_stage\"
driving = \"engine\"
driven = \"flywheel\"
base_radii = [0.02, 0.04]
teeth = 21
shaft_order = 0.5
stiffness = {{ shape = \"cosine\", mean = 1e8, amplitude = 1e7 }}
"
    )
    .replace(
        "orders = [{ order = 0.5, amplitude = 10.0 }, { order = 2.0, amplitude = 60.0 }]",
        "orders = [{ order = 2.0, amplitude = 60.0 }]",
    )
    .replace("harmonics = { count = 8 }", "harmonics = { count = 24 }");
    let s = Scene::from_str(&text, "stage.toml").unwrap();
    assert_eq!(s.fundamental_order, 0.5);
    let stage = s.model.elements()[0].gear_stage().unwrap();
    assert_eq!(stage.mesh_order(), Some(21));
    // With `fundamental.order = 1` the half mesh order is refused at the stage's field.
    let err = Scene::from_str(
        &text.replace("{ rpm = 3000 }", "{ rpm = 3000, order = 1 }"),
        "stage.toml",
    )
    .unwrap_err();
    assert_eq!(
        err.path.as_deref(),
        Some("elements[0].shaft_order"),
        "{err}"
    );
    assert!(err.to_string().contains("fundamental's order 1"), "{err}");
}

/// A cosine mesh stiffness of zero amplitude is constant: it does not choose the fundamental
/// (it chose order 0.1 from 23 teeth at shaft order 0.4, review finding), as `constant` does not.
#[test]
fn a_flat_cosine_stage_does_not_choose_the_fundamental() {
    let text = format!(
        "{SCENE}
[[elements]]
name = \"stage\"
type = \"gear_stage\"
driving = \"engine\"
driven = \"flywheel\"
base_radii = [0.02, 0.04]
teeth = 23
shaft_order = 0.4
stiffness = {{ shape = \"cosine\", mean = 1e8, amplitude = 0.0 }}
"
    );
    let flat = Scene::from_str(&text, "flat.toml").unwrap();
    let constant = Scene::from_str(
        &text.replace(
            "shape = \"cosine\", mean = 1e8, amplitude = 0.0",
            "shape = \"constant\", stiffness = 1e8",
        ),
        "constant.toml",
    )
    .unwrap();
    assert_eq!(flat.fundamental_order, constant.fundamental_order);
    assert_eq!(flat.fundamental_order, 0.5);
}
