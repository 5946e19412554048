//! `hbal check`, `solve` and `sweep` of a scene on several base frequencies: the summary, the
//! JSON (equal to the library's analysis), the files, the exit codes, the refused flags.

use crate::common::cli::scenes_dir;
use crate::common::hbal;
use hbal::analysis::{torus_solve, TorusSolveSettings};

fn scene() -> String {
    scenes_dir()
        .join("two_stage_train_torus.toml")
        .to_str()
        .unwrap()
        .to_string()
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn solve_prints_labelled_lines_and_its_json_is_the_library_analysis() {
    let p = scene();
    let out = hbal(&["check", &p]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("stage1 (order 23, cap 4, grid 16)") && text.contains("689 lines"),
        "{text}"
    );

    let dir = std::env::temp_dir().join(format!("hbal-torus-cli-{}", std::process::id()));
    let out = hbal(&["solve", &p, "--json", "--out", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let scene = hbal::scene::Scene::load(std::path::Path::new(&p)).unwrap();
    let a = torus_solve(&scene, &TorusSolveSettings::default()).unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.trim() == a.to_json(),
        "the CLI's JSON is the analysis's"
    );
    assert_eq!(doc["speed"], 3000.0);
    // The mean mesh forces carry the engine torque through each stage: 150 N m / r_b1 and
    // 150 × 67/23 N m / r_b3 (an invariant of the converged balance).
    let mean = |e: usize| doc["forces"][e]["mean"].as_f64().unwrap();
    assert!(
        (mean(0) - 150.0 / 0.02875).abs() < 1e-6 * mean(0),
        "{}",
        mean(0)
    );
    assert!(
        (mean(1) - 150.0 * 67.0 / 23.0 / 0.0285).abs() < 1e-6 * mean(1),
        "{}",
        mean(1)
    );
    let lines = std::fs::read_to_string(dir.join("lines.csv")).unwrap();
    let header = lines.lines().next().unwrap();
    assert_eq!(
        header,
        "what,name,line,k_engine,k_stage1,k_stage2,order,hz,amplitude,phase_deg"
    );
    // Every line of 8 DOFs, 2 coordinates and 2 forces, and the header.
    assert_eq!(lines.lines().count(), 1 + 12 * 689);
    assert!(
        lines.contains("force,stage1,3 stage1,0,3,0,6.9e1,3.45"),
        "{}",
        &lines[..400]
    );
    assert!(dir.join("spectrum.svg").exists());

    let out = hbal(&["solve", &p]);
    let text = String::from_utf8_lossy(&out.stdout);
    for want in [
        "on several base frequencies",
        "element stage1 force: mean 5.2174e3",
        "3 stage1 − stage2",
        "stability: not computed",
    ] {
        assert!(text.contains(want), "{want}: {text}");
    }
}

#[test]
fn sweep_writes_order_cuts_and_a_waterfall_and_marks_failures() {
    let p = scene();
    let dir = std::env::temp_dir().join(format!("hbal-torus-sweep-{}", std::process::id()));
    let out = hbal(&[
        "sweep",
        &p,
        "--from",
        "2000",
        "--to",
        "2200",
        "--points",
        "5",
        "--out",
        dir.to_str().unwrap(),
        "--output",
        "stage2",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let cuts = std::fs::read_to_string(dir.join("order_cuts.csv")).unwrap();
    assert_eq!(
        cuts.lines().next().unwrap(),
        "speed_rpm,element,line,order,amplitude,converged"
    );
    assert_eq!(
        cuts.lines().count(),
        1 + 2 * hbal::analysis::CUTS_PER_ELEMENT * 5
    );
    for f in ["points.csv", "order_cuts.svg", "waterfall.svg"] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let svg = std::fs::read_to_string(dir.join("order_cuts.svg")).unwrap();
    assert!(svg.contains("stage2"), "the plot shows stage 2's cuts");
    // Through 2834-2935 rpm the rattling points are marked, and the exit code says so.
    let out = hbal(&[
        "sweep", &p, "--from", "2884", "--to", "2935", "--points", "3", "--json",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let failed = doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["converged"] == false)
        .count();
    assert!(failed > 0, "{doc}");
    // Peaks come from converged points only.
    let converged: Vec<f64> = doc["points"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["converged"] == true)
        .map(|p| p["speed"].as_f64().unwrap())
        .collect();
    for c in doc["order_cuts"].as_array().unwrap() {
        let at = &c["peak"][1];
        assert!(
            at.is_null() || converged.contains(&at.as_f64().unwrap()),
            "{c}"
        );
    }
    assert!(
        stderr(&out).contains("did not converge"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn flags_of_one_fundamental_are_refused_on_the_torus() {
    let p = scene();
    for args in [
        vec!["solve", &p, "--method", "anderson"],
        vec!["solve", &p, "--harmonics", "16"],
        vec!["solve", &p, "--no-fallback"],
        vec!["sweep", &p, "--to", "3000", "--all-branches"],
        vec!["sweep", &p, "--to", "3000", "--output", "crank"],
        vec!["sweep", &p, "--to", "3000", "--points", "1"],
        vec![
            "report",
            &p,
            "--out",
            "/nonexistent-hbal-dir/x",
            "--from",
            "1000",
        ],
        vec!["compare", &p],
    ] {
        let out = hbal(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).is_empty());
    }
    let out = hbal(&["solve", &p, "--method", "anderson"]);
    assert!(
        stderr(&out).contains("--method applies to one fundamental"),
        "{}",
        stderr(&out)
    );
}
