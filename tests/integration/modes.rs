//! `hbal modes`: natural frequencies against the closed form of a two-inertia gear pair, the
//! one-/two-tooth bounds, critical speeds where the order lines cross, and the files.

use hbal::report::natural_frequencies;
use hbal::scene::Scene;
use hbal::{HarmonicBalance, HarmonicBasis, Newton};
use std::f64::consts::TAU;

/// Two inertias on a constant mesh (no ground): one rigid mode and `ω² = k (r1²/J1 + r2²/J2)`.
const PAIR: &str = r#"
dofs = ["pinion", "gear"]
mass = [[1e-3, 0.0], [0.0, 4e-3]]
fundamental = { rpm = 3000 }
harmonics = { count = 24 }
loads = [
  { dof = "pinion", order = 0, cos = 20.0 },
  { dof = "gear", order = 0, cos = -40.0 },
  { dof = "pinion", order = 1, cos = 1.0 },
]

[[elements]]
name = "mesh"
type = "gear_stage"
driving = "pinion"
driven = "gear"
base_radii = [0.02, 0.04]
teeth = 20
stiffness = { shape = "rectangular", one_tooth = 3e8, two_tooth = 5e8, contact_ratio = 1.5 }
damping = { proportional = 1e-6 }
"#;

#[test]
fn gear_pair_frequencies_equal_the_closed_form() {
    let s = Scene::from_str(PAIR, "pair.toml").unwrap();
    let hb =
        HarmonicBalance::new(&s.model, HarmonicBasis::new(s.basis.omega(), 24).unwrap()).unwrap();
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    assert!(sol.is_converged());
    let f = natural_frequencies(&s.model, &sol, f64::INFINITY).unwrap();
    assert_eq!(f.rigid, 1);
    assert_eq!(f.mean[0], 0.0);
    let hz = |k: f64| (k * (0.02f64.powi(2) / 1e-3 + 0.04f64.powi(2) / 4e-3)).sqrt() / TAU;
    for (got, k) in [(f.lower[1], 3e8), (f.upper[1], 5e8), (f.mean[1], 4e8)] {
        // The mean over 256 samples of a jump at 0.5: exact.
        assert!((got - hz(k)).abs() < 1e-9 * hz(k), "{got} vs {}", hz(k));
    }
    // The mode shape: the two gears against each other along the line of action,
    // r1 φ1 / (r2 φ2) = -(J2/r2²)/(J1/r1²)... i.e. J1 φ1 / r1 = -J2 φ2 / r2 (no net momentum).
    let (p1, p2) = (f.shapes[(0, 1)], f.shapes[(1, 1)]);
    assert!((1e-3 * p1 / 0.02 + 4e-3 * p2 / 0.04).abs() < 1e-9 * (1e-3 * p1 / 0.02).abs());
}

#[test]
fn cli_lists_modes_and_critical_speeds() {
    let dir = std::env::temp_dir().join(format!("hbal-modes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("pair.toml");
    std::fs::write(&scene, PAIR).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args([
            "modes",
            scene.to_str().unwrap(),
            "--from",
            "0",
            "--to",
            "20000",
            "--json",
            "--out",
        ])
        .arg(dir.join("out"))
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mean = doc["modes"][1]["mean_hz"].as_f64().unwrap();
    // Orders 1 (the load) and 20 (the mesh); the mesh order meets the mode at 60 f / 20 rpm.
    let orders: Vec<f64> = doc["orders"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(orders, [1.0, 20.0]);
    let crit = doc["critical_speeds"].as_array().unwrap();
    let mesh = crit.iter().find(|c| c["order"] == 20.0).unwrap();
    assert!((mesh["speed"].as_f64().unwrap() - 60.0 * mean / 20.0).abs() < 1e-9 * mean);
    assert_eq!(mesh["mode"], 2);
    // Order 1 would meet it at 60 f rpm, beyond --to: not listed.
    assert!(crit.iter().all(|c| c["order"] != 1.0) || 60.0 * mean <= 20000.0);
    let csv = std::fs::read_to_string(dir.join("out/modes.csv")).unwrap();
    assert!(
        csv.starts_with("mode,mean_hz,lower_hz,upper_hz,pinion,gear\n"),
        "{csv}"
    );
    assert!(dir.join("out/campbell.svg").exists());
    // Bad range: exit 2.
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args([
            "modes",
            scene.to_str().unwrap(),
            "--from",
            "100",
            "--to",
            "50",
        ])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(2));
    let _ = std::fs::remove_dir_all(&dir);
}
