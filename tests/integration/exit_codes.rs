//! The exit-code contract on every subcommand: 0 success, 1 a numerical failure (results still
//! written and marked), 2 bad input or an unusable `--out`, found before the work starts.

use crate::common;

use common::hbal;
use std::path::{Path, PathBuf};

fn example(name: &str) -> String {
    format!("{}/examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("exit_codes")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.parent().unwrap()).unwrap();
    d
}

/// A scene file `name` in the test directory with `text` (names carry the test's tag: the
/// tests run in parallel).
fn scene(name: &str, text: &str) -> String {
    let p = dir("scenes").parent().unwrap().join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// The Duffing oscillator forced so hard (1e100) that the residual overflows: a numerical
/// failure of valid input.
fn overflowing(tag: &str) -> String {
    let text = std::fs::read_to_string(example("duffing.toml"))
        .unwrap()
        .replace("cos = 0.1 }", "cos = 1e100 }");
    scene(&format!("overflowing_{tag}.toml"), &text)
}

/// A static-only scene (no dynamic load): its spectrum is empty.
fn static_only(tag: &str) -> String {
    scene(
        &format!("static_only_{tag}.toml"),
        "dofs = [\"x\"]\nmass = [[1.0]]\nstiffness = [[4.0]]\ndamping = [[0.1]]\n\
         fundamental = { rad_s = 1.0 }\nharmonics = { count = 4 }\n\
         loads = [{ dof = \"x\", order = 0, cos = 2.0 }]\n",
    )
}

/// Runs hbal and checks the exit code and a piece of stderr.
fn expect(args: &[&str], code: i32, stderr_has: &str) -> std::process::Output {
    let out = hbal(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(
        err.contains(stderr_has),
        "{args:?}: `{stderr_has}` not in: {err}"
    );
    out
}

/// An `--out` that cannot be created: a path under a regular file.
fn unusable_out(tag: &str) -> String {
    let file = dir(&format!("a_file_{tag}"));
    std::fs::write(&file, "").unwrap();
    file.join("sub").to_str().unwrap().to_string()
}

#[test]
fn solve_exit_codes() {
    let duffing = example("duffing.toml");
    expect(&["solve", &duffing], 0, "");
    // A static-only scene with --out: converged, no spectrum to draw, still 0.
    let out_dir = dir("static");
    let out = expect(
        &[
            "solve",
            &static_only("solve_exit_codes"),
            "--json",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        0,
        "",
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["converged"], true);
    assert!(out_dir.join("harmonics.csv").exists());
    assert!(out_dir.join("elements.csv").exists());
    assert!(!out_dir.join("spectrum.svg").exists());
    // A numerical failure at the start names the scene: 1, not 2.
    expect(
        &["solve", &overflowing("solve_exit_codes")],
        1,
        "overflowing_solve_exit_codes.toml: non-finite value",
    );
    // An unusable --out before any work.
    expect(
        &[
            "solve",
            &duffing,
            "--out",
            &unusable_out("solve_exit_codes"),
        ],
        2,
        "cannot create the directory",
    );
}

#[test]
fn sweep_and_compare_exit_codes() {
    let duffing = example("duffing.toml");
    expect(&["sweep", &duffing, "--from", "0.5", "--to", "0.6"], 0, "");
    // The branch stops before --to: 1, and says why.
    expect(
        &[
            "sweep",
            &duffing,
            "--from",
            "0.5",
            "--to",
            "2.5",
            "--max-points",
            "2",
        ],
        1,
        "the branch stopped",
    );
    // Negative numbers are values, and refused as speeds with the reason.
    expect(
        &["sweep", &duffing, "--to", "-1"],
        2,
        "--to must be a finite speed > 0",
    );
    expect(
        &[
            "sweep",
            &duffing,
            "--to",
            "1",
            "--out",
            &unusable_out("sweep_and_compare_exit_codes"),
        ],
        2,
        "cannot create the directory",
    );
    expect(
        &["sweep", &duffing, "--to", "1", "--output", "nothing"],
        2,
        "--output `nothing` is neither an element (spring) nor a DOF (x)",
    );
    // compare: refuses an unusable --out before the time-domain run.
    let out = expect(
        &[
            "compare",
            &duffing,
            "--out",
            &unusable_out("sweep_and_compare_exit_codes"),
        ],
        2,
        "cannot create the directory",
    );
    assert!(out.stdout.is_empty(), "nothing computed");
    expect(
        &["compare", &overflowing("sweep_and_compare_exit_codes")],
        1,
        "non-finite value",
    );
}

#[test]
fn modes_check_and_report_exit_codes() {
    let duffing = example("duffing.toml");
    expect(&["check", &duffing], 0, "");
    expect(
        &["check", &static_only("modes_check_and_report_exit_codes")],
        0,
        "",
    );
    expect(
        &[
            "check",
            &scene("broken.toml", "dofs = [\"x\"]\nmass = [[-1.0]]\n"),
        ],
        2,
        "broken.toml",
    );
    expect(&["modes", &duffing], 0, "");
    expect(
        &["modes", &duffing, "--from", "2", "--to", "1"],
        2,
        "need 0 <= from < to",
    );
    expect(
        &["modes", &overflowing("modes_check_and_report_exit_codes")],
        1,
        "non-finite value",
    );
    // report: a numerical failure of the solve is on the page, and the exit code is 1.
    let out_dir = dir("report_failing");
    expect(
        &[
            "report",
            &overflowing("modes_check_and_report_exit_codes"),
            "--out",
            out_dir.to_str().unwrap(),
        ],
        1,
        "non-finite value",
    );
    let html = std::fs::read_to_string(out_dir.join("report.html")).unwrap();
    assert!(
        html.contains("class=\"fail\">no solution"),
        "the failure is on the page"
    );
    expect(
        &[
            "report",
            &duffing,
            "--out",
            &unusable_out("modes_check_and_report_exit_codes"),
        ],
        2,
        "cannot create the directory",
    );
}
