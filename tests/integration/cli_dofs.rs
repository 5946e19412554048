//! `hbal sweep --dofs`: which DOFs' harmonics and response plots a sweep writes. A large model
//! writes those of the DOFs that elements and loads act on by default (max |q| of every DOF
//! always); a small one every DOF; `all` and a list of names choose; an unknown name is bad
//! input.

use crate::common;

use common::hbal;

use std::path::{Path, PathBuf};

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenes")
        .join(name)
}

fn json(out: &std::process::Output) -> serde_json::Value {
    assert!(
        out.status.code() == Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

/// A short run-up of the 1000-DOF drivetrain without stability.
fn drivetrain(extra: &[&str]) -> std::process::Output {
    let s = scene("large/drivetrain_1000.toml");
    let mut args = vec![
        "sweep",
        s.to_str().unwrap(),
        "--from",
        "1000",
        "--to",
        "1002",
        "--no-stability",
        "--no-error-estimate",
    ];
    args.extend_from_slice(extra);
    hbal(&args)
}

#[test]
fn a_large_model_reports_the_dofs_of_its_elements_and_loads() {
    let dir = std::env::temp_dir().join(format!("hbal-cli-dofs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let doc = json(&drivetrain(&["--json", "--out", dir.to_str().unwrap()]));
    let names: Vec<&str> = doc["harmonics_dofs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 15, "{names:?}");
    for dof in ["throw1", "flywheel", "hub", "gear1", "vehicle"] {
        assert!(names.contains(&dof), "{dof} in {names:?}");
    }
    assert!(!names.contains(&"input.1"), "{names:?}");
    let points = doc["points"].as_array().unwrap();
    assert!(points.len() >= 2);
    for p in points {
        assert_eq!(p["max_abs"].as_array().unwrap().len(), 1000);
        assert_eq!(p["harmonics"].as_array().unwrap().len(), 15);
    }
    // branch.csv: max |q| of all 1000 DOFs, the 33 amplitudes of the 15; 15 plots.
    let csv = std::fs::read_to_string(dir.join("branch.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let count = |prefix: &str| header.iter().filter(|h| h.starts_with(prefix)).count();
    assert_eq!(count("max_abs_"), 1000);
    assert_eq!(count("amp_"), 15 * 33);
    assert_eq!(count("amp_throw1_k"), 33);
    assert_eq!(count("amp_input.1_k"), 0);
    // order_cuts.csv: the same 15 DOFs (and every element), each order's amplitude the one
    // branch.csv has for that DOF and order.
    let cuts = std::fs::read_to_string(dir.join("order_cuts.csv")).unwrap();
    let cut_header: Vec<&str> = cuts.lines().next().unwrap().split(',').collect();
    assert!(!cut_header
        .iter()
        .any(|h| h.starts_with("amp_input.1_order_")));
    assert!(cut_header.iter().any(|h| h.starts_with("amp_u(")));
    let first_row = |text: &str| -> Vec<f64> {
        let line = text.lines().nth(1).unwrap();
        line.split(',')
            .map(|v| v.parse().unwrap_or(f64::NAN))
            .collect()
    };
    let (cut_row, branch_row) = (first_row(&cuts), first_row(&csv));
    let mut compared = 0;
    for (c, name) in cut_header.iter().enumerate() {
        let Some(order) = name.strip_prefix("amp_throw1_order_") else {
            continue;
        };
        let b = header
            .iter()
            .position(|h| h.starts_with("amp_throw1_k") && h.ends_with(&format!("_order_{order}")))
            .unwrap_or_else(|| panic!("order {order} of throw1 in branch.csv"));
        let (x, y) = (cut_row[c], branch_row[b]);
        assert!(
            (x - y).abs() <= 1e-12 * y.abs(),
            "order {order}: {x} vs {y}"
        );
        compared += 1;
    }
    assert!(compared >= 2, "{compared} orders of throw1 compared");
    let plots = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            name.to_string_lossy().starts_with("frequency_response_")
        })
        .count();
    assert_eq!(plots, 15);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn dofs_chosen_by_name_or_all() {
    let doc = json(&drivetrain(&[
        "--json",
        "--dofs",
        "vehicle, throw1,vehicle",
    ]));
    assert_eq!(
        doc["harmonics_dofs"],
        serde_json::json!(["throw1", "vehicle"])
    );
    assert_eq!(doc["points"][0]["harmonics"].as_array().unwrap().len(), 2);
    let doc = json(&drivetrain(&["--json", "--dofs", "all"]));
    assert_eq!(doc["harmonics_dofs"].as_array().unwrap().len(), 1000);
    assert_eq!(
        doc["points"][0]["harmonics"].as_array().unwrap().len(),
        1000
    );
    // A small model: every DOF by default.
    let s = scene("gear_backlash.toml");
    let out = hbal(&["sweep", s.to_str().unwrap(), "--to", "0.85", "--json"]);
    let doc = json(&out);
    assert_eq!(doc["harmonics_dofs"], doc["dofs"]);
}

#[test]
fn an_unknown_dof_is_bad_input() {
    for (list, named) in [
        ("throw1,nosuch", "`nosuch`"),
        ("throw1,,hub", "an empty name"),
    ] {
        let out = drivetrain(&["--dofs", list]);
        assert_eq!(out.status.code(), Some(2), "{list}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--dofs") && err.contains(named), "{err}");
    }
}
