//! The library's modes analysis (`hbal::analysis::modes`, issue 32) is what `hbal modes
//! --json` prints; its critical speeds are where the order lines meet the natural
//! frequencies.

use crate::common::json_diff::first_difference;
use hbal::analysis::{modes, ModesSettings};
use hbal::scene::Scene;
use serde_json::Value;
use std::path::Path;

#[test]
fn the_cli_json_is_the_serialised_library_modes() {
    for name in [
        "free_free_drivetrain.toml",
        "two_shaft_6000rpm.toml",
        "duffing.toml",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/scenes")
            .join(name);
        let scene = Scene::load(&path).unwrap();
        let settings = ModesSettings {
            from: Some(0.0),
            to: Some(3.0 * scene.basis.omega() / scene.omega_per_speed),
            ..ModesSettings::default()
        };
        let a = modes(&scene, &settings).unwrap();
        let library: Value = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
            .args(["modes", "--json", "--from", "0"])
            .args(["--to", &settings.to.unwrap().to_string()])
            .arg(&path)
            .output()
            .unwrap();
        let cli: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(first_difference(&library, &cli, ""), None, "{name}");
        assert_eq!(a.exit_code(), 0);
        // Every critical speed puts its order line on its mode's mean frequency.
        let nf = a.natural.as_ref().unwrap();
        for c in &a.critical {
            let line_hz = c.order * c.speed * a.per_unit / std::f64::consts::TAU;
            let f = nf.mean[c.mode - 1];
            assert!((line_hz - f).abs() <= 1e-12 * f, "{name}: {c:?}");
            assert!(c.speed >= 0.0 && c.speed <= settings.to.unwrap());
        }
    }
    // The Duffing oscillator linearised at its orbit's mean coordinate (x = 0, where the
    // tangent stiffness is k = 1 with m = 1): one mode at exactly 1/2π Hz.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/duffing.toml");
    let a = modes(&Scene::load(&path).unwrap(), &ModesSettings::default()).unwrap();
    let f = a.natural.unwrap().mean[0];
    assert!((f - 1.0 / std::f64::consts::TAU).abs() < 1e-12, "{f}");
    let bad = ModesSettings {
        from: Some(2.0),
        to: Some(1.0),
        ..ModesSettings::default()
    };
    let e = modes(&Scene::load(&path).unwrap(), &bad).unwrap_err();
    assert!(e.to_string().contains("need 0 <= from < to"), "{e}");
    assert_eq!(e.exit_code(), 2);
}

/// The critical speeds come by speed, as a run-up meets them (issue 36; they came by order):
/// on the free-free drivetrain orders 1.5, 2 and 3 meet modes 3 and 4 interleaved.
#[test]
fn critical_speeds_come_by_speed() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/free_free_drivetrain.toml");
    let scene = Scene::load(&path).unwrap();
    let settings = ModesSettings {
        from: Some(800.0),
        to: Some(6000.0),
        ..ModesSettings::default()
    };
    let a = modes(&scene, &settings).unwrap();
    let speeds: Vec<f64> = a.critical.iter().map(|c| c.speed).collect();
    assert!(speeds.len() >= 6, "{speeds:?}");
    assert!(speeds.windows(2).all(|w| w[0] <= w[1]), "{speeds:?}");
    // Not by order: a lower order comes after a higher one somewhere.
    assert!(a.critical.windows(2).any(|w| w[1].order < w[0].order));
    // Order 3 meets mode 3 first, at 960 rpm.
    assert_eq!((a.critical[0].order, a.critical[0].mode), (3.0, 3));
    assert!(
        (a.critical[0].speed - 960.29).abs() < 0.01,
        "{}",
        a.critical[0].speed
    );
}
