//! `hbal` with the exact piecewise solution on a model that floats free and with `--out`.

use super::piecewise_exact::{run, scene};

/// A model that floats free: the rigid motion separated, the exact method in `hbal compare`
/// agreeing with the time domain far below harmonic balance at H = 16 (per quantity too, by
/// its closed form in time); with mean loads that do
/// not balance, refused by the net torque.
#[test]
fn a_model_that_floats_free() {
    let dir = std::env::temp_dir().join(format!("hbal-exact-free-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let free = dir.join("free.toml");
    std::fs::write(&free, FREE_FREE).unwrap();
    let free = free.to_str().unwrap();
    let (code, out, err) = run(&["solve", free, "--method", "piecewise_exact"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("2 neutral"), "{out}");
    let (code, out, err) = run(&["compare", free, "--json"]);
    assert_eq!(code, Some(0), "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let field = |name: &str, pointer: &str| {
        json["methods"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["method"] == name)
            .and_then(|m| m.pointer(pointer).and_then(|v| v.as_f64()))
            .unwrap_or_else(|| panic!("{name} missing: {out}"))
    };
    let error_of = |name: &str| field(name, "/error_vs_time_domain");
    assert!(error_of("piecewise_exact") < 1e-7, "{out}");
    assert!(error_of("newton") > 1e-5, "{out}");
    // Per quantity over the time series: the exact method by its closed form (its harmonics
    // 0..16 alone miss the ringing after each jump), harmonic balance by its harmonics.
    let worst_of = |name: &str| field(name, "/worst_quantity_vs_time_domain/error");
    eprintln!(
        "worst quantity: exact {:.1e}, newton {:.1e}",
        worst_of("piecewise_exact"),
        worst_of("newton")
    );
    assert!(worst_of("piecewise_exact") < 1e-5, "{out}");
    assert!(
        worst_of("newton") > 1e2 * worst_of("piecewise_exact"),
        "{out}"
    );
    let unbalanced = dir.join("unbalanced.toml");
    std::fs::write(&unbalanced, FREE_FREE.replace("cos = -5.0", "cos = -4.0")).unwrap();
    let (code, _, err) = run(&[
        "solve",
        unbalanced.to_str().unwrap(),
        "--method",
        "piecewise_exact",
    ]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("balance") || err.contains("net"), "{err}");
}

#[test]
fn the_exact_methods_files_show_the_ringing() {
    // --out at 60 rpm: time_series.csv from the closed form, 16 samples per period of the
    // highest natural frequency (771 of them per mesh period), its largest value the exact
    // extreme to the sampling; the harmonics 0..32 would top out at 4.18e-5.
    let dir = std::env::temp_dir().join(format!("hbal-exact-out-{}", std::process::id()));
    let (code, _, err) = run(&[
        "solve",
        &scene("two_shaft_60rpm.toml"),
        "--method",
        "piecewise_exact",
        "--no-stability",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let text = std::fs::read_to_string(dir.join("time_series.csv")).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let q: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
        .collect();
    assert!(q.len() > 12_000, "{}", q.len());
    let max = q.iter().fold(0.0f64, |m, &v| m.max(v));
    assert!(max > 5.7e-5 && max <= 5.7589e-5, "{max:e}");
}

/// Two inertias joined only by a rectangular mesh, the mean torques balanced.
const FREE_FREE: &str = r#"
dofs = ["pinion", "gear"]
mass = [[1e-3, 0], [0, 2e-3]]
fundamental = { rad_s = 3000 }
harmonics = { count = 16 }
loads = [
  { dof = "pinion", order = 0, cos = 5.0 },
  { dof = "gear", order = 0, cos = -5.0 },
  { dof = "pinion", order = 1, cos = 0.5 },
]

[[elements]]
name = "mesh"
type = "mesh_stiffness"
connects = { pinion = 1.0, gear = -1.0 }
teeth = 1
profile = { shape = "rectangular", one_tooth = 2.5e5, two_tooth = 5e5, contact_ratio = 1.5 }
damping = { proportional = 5e-6 }
"#;

#[test]
fn a_speed_sweep_with_the_exact_method() {
    // Evenly spaced speeds, each solved exactly: its own estimate (the harmonics 0..H exact),
    // extremes from the closed form (5.7589e-5 at 60 rpm, as hbal solve) and the exact
    // monodromy matrix's multipliers; not harmonic-balance continuation from an exact start.
    let (code, out, err) = run(&[
        "sweep",
        &scene("two_shaft_60rpm.toml"),
        "--method",
        "piecewise_exact",
        "--from",
        "60",
        "--to",
        "600",
        "--points",
        "3",
        "--json",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 3);
    let speeds: Vec<f64> = points
        .iter()
        .map(|p| p["speed"].as_f64().unwrap())
        .collect();
    assert_eq!(speeds, [60.0, 330.0, 600.0]);
    for p in points {
        assert_eq!(p["error_estimate_harmonics"].as_f64(), Some(1e-15), "{p}");
        assert_eq!(p["orbit_correction"].as_f64(), Some(0.0), "{p}");
        assert_eq!(p["stable"], true);
    }
    let max = points[0]["max_abs"][0].as_f64().unwrap();
    assert!((max - 5.7589e-5).abs() < 1e-9, "{max:e}");
}
