//! `hbal sweep --all-branches`: the period-2 orbit of the gear pair's parametric resonance out
//! of one sweep, with the period doubling located; the bad uses of the flag; automatic harmonics.

use crate::common;

use common::hbal;

use std::path::{Path, PathBuf};

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/gear_backlash_period_doubling.toml")
}

/// W_pd of the independent reference (tests/data/period2/gear_backlash_pd.json).
const W_PD: f64 = 2.1654112939172774;

#[test]
fn all_branches_finds_the_period_two_orbit() {
    let dir = std::env::temp_dir().join(format!("hbal-cli-branches-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let s = scene();
    let out = hbal(&[
        "sweep",
        s.to_str().unwrap(),
        "--from",
        "2.3",
        "--to",
        "2.0",
        "--all-branches",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // The main branch says where its stability changes, located to the reference's 1e-6.
    let located: Vec<f64> = doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|p| p["bifurcation_speed"].as_f64())
        .collect();
    assert_eq!(located.len(), 1, "{located:?}");
    assert!((located[0] - W_PD).abs() < 1e-6, "{}", located[0]);
    let branches = doc["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 1);
    let b = &branches[0];
    assert_eq!(b["bifurcation"], "PeriodDoubling");
    assert_eq!(b["period_multiple"], 2);
    assert_eq!(b["reached"], true, "{}", b["stop"]);
    assert!((b["from_speed"].as_f64().unwrap() - W_PD).abs() < 1e-6);
    let points = b["points"].as_array().unwrap();
    let last = points.last().unwrap();
    assert_eq!(last["speed"], 2.0);
    assert_eq!(last["stable"], true);
    // Harmonic 1 of the period-2 orbit is shaft order 1/2, and it is there.
    let h1 = &last["harmonics"][0][1];
    assert_eq!(h1["order"], 0.5);
    assert!(
        h1["cos"]
            .as_f64()
            .unwrap()
            .hypot(h1["sin"].as_f64().unwrap())
            > 0.1
    );
    let csv = std::fs::read_to_string(dir.join("branch_1.csv")).unwrap();
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .ends_with("bifurcation_speed,error_estimate,error_estimate_harmonics"));
    // Every point carries its error estimates (against 2H); its harmonics 0..H are at most
    // as far off as the whole periodic solution.
    for p in points {
        let e = p["error_estimate"].as_f64().unwrap();
        assert!((1e-15..1e-2).contains(&e), "{e}");
        let kept = p["error_estimate_harmonics"].as_f64().unwrap();
        assert!((1e-15..=e).contains(&kept), "{kept} vs {e}");
    }
    assert_eq!(csv.lines().count(), points.len() + 1);
    let svg = std::fs::read_to_string(dir.join("frequency_response_x.svg")).unwrap();
    assert!(
        svg.contains("period 2T"),
        "the plot names the period-2 branch"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn all_branches_needs_stability_and_a_speed_sweep() {
    let s = scene();
    let s = s.to_str().unwrap();
    let out = hbal(&[
        "sweep",
        s,
        "--to",
        "2.0",
        "--all-branches",
        "--no-stability",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--all-branches needs the stability"));
    let out = hbal(&[
        "sweep",
        s,
        "--to",
        "0.1",
        "--from",
        "0.01",
        "--all-branches",
        "--parameter",
        "loads[1].cos",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--parameter"));
}

/// The period-2 orbits form a loop between the two period doublings (2.1654 and 1.8201, the
/// reference's tongue edges): followed from the upper one, the branch comes back onto the
/// period-1 branch at the lower one (instead of going round the loop again), and the lower
/// doubling is not switched a second time. Swept upwards, the doublings are found although the
/// points before them have complex multipliers only.
#[test]
fn period_two_loop_ends_where_it_rejoins() {
    let s = scene();
    let s = s.to_str().unwrap();
    let out = hbal(&[
        "sweep",
        s,
        "--from",
        "2.3",
        "--to",
        "1.0",
        "--all-branches",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let branches = doc["branches"].as_array().unwrap();
    assert_eq!(branches.len(), 1, "the lower doubling is the same loop");
    let b = &branches[0];
    assert!(
        b["stop"].as_str().unwrap().starts_with("rejoined"),
        "{}",
        b["stop"]
    );
    let end = b["points"].as_array().unwrap().last().unwrap()["speed"]
        .as_f64()
        .unwrap();
    // The reference's lower tongue edge.
    assert!((end - 1.8201405529191677).abs() < 1e-4, "{end}");
    let out = hbal(&[
        "sweep",
        s,
        "--from",
        "1.7",
        "--to",
        "2.3",
        "--all-branches",
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let from: Vec<f64> = doc["branches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["from_speed"].as_f64().unwrap())
        .collect();
    assert_eq!(from.len(), 2, "{from:?}");
    assert!((from[0] - 1.8201405529191677).abs() < 1e-6, "{from:?}");
    assert!((from[1] - W_PD).abs() < 1e-6, "{from:?}");
}

/// `--harmonics auto` and `harmonics = { auto = true }`: H doubled until the error estimate is
/// below the tolerance, every level reported; bad settings name the field.
#[test]
fn automatic_harmonics_on_the_command_line_and_in_scenes() {
    let backlash = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/duffing.toml");
    let out = hbal(&[
        "solve",
        backlash.to_str().unwrap(),
        "--harmonics",
        "auto",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let est = doc["error_estimate"]["relative"].as_f64().unwrap();
    assert!((1e-15..=1e-6).contains(&est), "{est}");
    assert_eq!(doc["auto_harmonics"]["reached"], true);
    assert!(!doc["auto_harmonics"]["levels"]
        .as_array()
        .unwrap()
        .is_empty());
    let dir = std::env::temp_dir().join(format!("hbal-auto-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = |harmonics: &str| {
        let text = std::fs::read_to_string(&backlash)
            .unwrap()
            .replace("harmonics = { count = 7 }", harmonics);
        let p = dir.join("s.toml");
        std::fs::write(&p, text).unwrap();
        hbal(&["solve", p.to_str().unwrap(), "--no-stability"])
    };
    // What automatic harmonics control, on the two-shaft model at 6000 rpm, where it matters:
    // its harmonics 0..H reach 1e-6 at H = 32, the periodic solution not below H = 512.
    let two_shaft = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/two_shaft_6000rpm.toml"),
    )
    .unwrap()
    .replace(
        "[harmonics]\ncount = 32\n",
        "[harmonics]\nauto = true\ncount = 32\nmax = 64\ncontrol = \"harmonics\"\n",
    );
    assert!(two_shaft.contains("control"));
    let p = dir.join("two_shaft.toml");
    std::fs::write(&p, two_shaft).unwrap();
    let solve = |harmonics: Option<&str>| {
        let mut args = vec!["solve", p.to_str().unwrap(), "--no-stability", "--json"];
        if let Some(h) = harmonics {
            args.extend(["--harmonics", h]);
        }
        let out = hbal(&args);
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        (out, doc)
    };
    // The scene's control, also with a bare `--harmonics auto`.
    for flag in [None, Some("auto"), Some("auto:harmonics")] {
        let (out, doc) = solve(flag);
        assert_eq!(out.status.code(), Some(0), "{flag:?}");
        assert_eq!(doc["auto_harmonics"]["control"], "harmonics", "{flag:?}");
        assert_eq!(doc["harmonics"], 32, "{flag:?}");
        let kept = doc["error_estimate"]["kept_harmonics"].as_f64().unwrap();
        assert!((1e-15..=1e-6).contains(&kept), "{kept}");
        assert!(doc["error_estimate"]["relative"].as_f64().unwrap() > 1e-4);
    }
    // `auto:solution` overrides it: harmonic balance stops at the cap H = 64 above the
    // tolerance, and the scene, linear with piecewise-constant coefficients, gets the exact
    // piecewise solution instead (exit 0), which says so.
    let (out, doc) = solve(Some("auto:solution"));
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(doc["auto_harmonics"]["control"], "solution");
    assert_eq!(doc["method"], "piecewise_exact");
    assert_eq!(doc["switched_to_exact"], true);
    assert_eq!(doc["harmonics"], 64);
    let levels = doc["auto_harmonics"]["levels"].as_array().unwrap();
    assert_eq!(levels[1]["harmonics"], 64);
    assert!(levels[1]["estimate"].as_f64().unwrap() > 1e-6);
    let text = hbal(&[
        "solve",
        p.to_str().unwrap(),
        "--no-stability",
        "--harmonics",
        "auto:solution",
    ]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("the exact piecewise solution answers instead"),
        "{text}"
    );
    // A sweep checks the estimate it controls along the branch: no warning here.
    let out = hbal(&[
        "sweep",
        p.to_str().unwrap(),
        "--from",
        "6000",
        "--to",
        "6030",
        "--no-stability",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("on the harmonics 0..H: H = 32"), "{err}");
    assert!(!err.contains("warning"), "{err}");
    // A cap below what the tolerance needs: the last level, exit 1 and a message.
    let out = scene("harmonics = { auto = true, count = 1, tolerance = 1e-12, max = 2 }");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("at the cap H = 2"), "{err}");
    // ... naming the quantity that limits it.
    assert!(err.contains("; worst quantity "), "{err}");
    for (bad, field) in [
        (
            "harmonics = { auto = true, tolerance = 0.0 }",
            "harmonics.tolerance",
        ),
        (
            "harmonics = { auto = true, tolerance = nan }",
            "harmonics.tolerance",
        ),
        (
            "harmonics = { auto = true, count = 16, max = 8 }",
            "harmonics.max",
        ),
        (
            "harmonics = { count = 7, tolerance = 1e-6 }",
            "harmonics.tolerance",
        ),
        ("harmonics = { samples = 64 }", "harmonics.count"),
        ("harmonics = { auto = true, count = 0 }", "harmonics.count"),
        (
            "harmonics = { auto = true, tolerance = 1e-300 }",
            "harmonics.tolerance",
        ),
        (
            "harmonics = { auto = true, max = 9000000000 }",
            "harmonics.max",
        ),
        (
            "harmonics = { auto = true, control = \"orders\" }",
            "harmonics.control",
        ),
        (
            "harmonics = { count = 7, control = \"harmonics\" }",
            "harmonics.control",
        ),
    ] {
        let out = scene(bad);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(field), "{bad}: {err}");
    }
    // A cap below the model's mesh order (20 teeth) is refused, naming the field and order.
    let gear = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/two_shaft_gear_pair.toml"),
    )
    .unwrap()
    .replace(
        "harmonics = { count = 64 }",
        "harmonics = { auto = true, count = 8, max = 16 }",
    );
    let p = dir.join("gear.toml");
    std::fs::write(&p, gear).unwrap();
    let out = hbal(&["solve", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("`max`") && err.contains(">= 20"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
