//! A scene without `fundamental` and `harmonics` (no operating point) is a model for `hbal
//! modes` and `hbal check`: natural frequencies and critical speeds without a solve; the
//! analyses that need an operating point refuse it by name (exit 2).

use crate::common::{cli::temp_dir, hbal};

const LINE: &str = r#"
loads = [{ dof = "b", order = 3, cos = 1.0 }]
[line]
disks = [{ name = "a", inertia = 1.0, damping = 1.0 }, { name = "b", inertia = 1.0 }]
shafts = [{ from = "a", to = "b", stiffness = 1e4, damping = 1.0 }]
"#;

#[test]
fn modes_and_check_need_no_operating_point() {
    let scene = hbal::scene::Scene::from_str(LINE, "line.toml").unwrap();
    assert!(!scene.operating_point);
    let dir = temp_dir("no-operating-point");
    let path = dir.join("line.toml");
    std::fs::write(&path, LINE).unwrap();
    let p = path.to_string_lossy();
    let out = hbal(&["check", &p]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(
        text.contains("no operating point") && text.contains("22.507908"),
        "{text}"
    );
    // ω = √(k (1/J_a + 1/J_b)) = √2e4 rad/s; order 3 meets it at 60 ω / (2π · 3) rpm.
    let omega = 2e4f64.sqrt();
    let critical = 60.0 * omega / (std::f64::consts::TAU * 3.0);
    let out = hbal(&["modes", &p, "--json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = crate::common::cli::json_of(&out);
    let speeds: Vec<f64> = json["critical_speeds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["speed"].as_f64().unwrap())
        .collect();
    assert_eq!(speeds.len(), 1, "{json}");
    assert!(
        (speeds[0] - critical).abs() < 1e-9 * critical,
        "{} vs {critical}",
        speeds[0]
    );
    for args in [
        vec!["solve", &p],
        vec!["sweep", &p, "--to", "100"],
        vec!["compare", &p],
        vec![
            "sweep",
            &p,
            "--parameter",
            "loads[0].cos",
            "--from",
            "1",
            "--to",
            "2",
        ],
    ] {
        let out = hbal(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("needs the scene's operating point"),
            "{args:?}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn half_an_operating_point_or_a_nonlinear_model_is_named() {
    let only = format!("fundamental = {{ rpm = 100 }}\n{LINE}");
    let err = hbal::scene::Scene::from_str(&only, "half.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("harmonics: is missing"), "{err}");
    let only = format!("harmonics = {{ count = 4 }}\n{LINE}");
    let err = hbal::scene::Scene::from_str(&only, "half.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("fundamental: is missing"), "{err}");
    let cubic = format!(
        "{LINE}\n[[elements]]\nname = \"c\"\ntype = \"cubic_spring\"\nconnects = {{ a = 1.0, b = -1.0 }}\nk = 0.0\nalpha = 1e6\n"
    );
    let scene = hbal::scene::Scene::from_str(&cubic, "cubic.toml").unwrap();
    let err = hbal::analysis::modes(&scene, &hbal::analysis::ModesSettings::default()).unwrap_err();
    assert!(
        err.to_string()
            .contains("needs the scene's operating point"),
        "{err}"
    );
    assert_eq!(err.exit_code(), 2);
}
