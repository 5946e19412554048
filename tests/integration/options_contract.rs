//! One contract for the options every subcommand shares (issue 32, bad input): a speed that is
//! not a finite positive number within range, and a scene a solve refuses, are bad input
//! (exit 2, nothing written) for `solve`, `sweep`, `modes` and `report` alike, found before any
//! work.

use crate::common::cli::temp_dir;
use crate::common::hbal;
use std::path::Path;

const TWO_SHAFT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/examples/scenes/two_shaft_6000rpm.toml"
);

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `report --to NaN` (or inf, -1) is refused before the solve and modes parts run: exit 2, one
/// error, no directory; `modes` and `sweep` refuse speeds out of range with the same message.
#[test]
fn a_bad_speed_is_refused_before_any_work_by_every_subcommand() {
    let dir = temp_dir("options_contract_report");
    let out_dir = dir.join("report");
    for bad in ["NaN", "inf", "-1", "1e300"] {
        let to = format!("--to={bad}");
        let out = hbal(&["report", TWO_SHAFT, &to, "--out", out_dir.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "report {bad}: {}", stderr(&out));
        let err = stderr(&out);
        assert_eq!(err.matches("error:").count(), 1, "{err}");
        assert!(
            err.contains("--to must be a finite speed > 0 (rpm)"),
            "{err}"
        );
        assert!(!err.contains("report: solving"), "{err}");
        assert!(
            !out_dir.exists(),
            "report {bad} wrote {}",
            out_dir.display()
        );
        for command in ["modes", "sweep"] {
            let out = hbal(&[command, TWO_SHAFT, &to]);
            assert_eq!(
                out.status.code(),
                Some(2),
                "{command} {bad}: {}",
                stderr(&out)
            );
            assert!(
                stderr(&out).contains("--to must be a finite speed > 0 (rpm)"),
                "{command} {bad}: {}",
                stderr(&out)
            );
        }
    }
    // `modes` alone may start at 0 rpm.
    let out = hbal(&["modes", TWO_SHAFT, "--from", "0", "--to", "9000", "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

fn write_scene(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// A scene `solve` refuses with exit 2 (a load above H, static loads that do not balance) is
/// refused by `sweep` the same way, before its first point, instead of exit 1 with nothing on
/// stdout.
#[test]
fn a_sweep_refuses_what_a_solve_refuses() {
    let dir = temp_dir("options_contract_sweep");
    let h0 = write_scene(
        &dir,
        "h0.toml",
        r#"dofs = ["x"]
mass = [[1.0]]
damping = [[0.02]]
stiffness = [[1.0]]
fundamental = { rad_s = 1.2 }
harmonics = { count = 0 }
loads = [{ dof = "x", order = 1, cos = 0.1 }]
"#,
    );
    let unbalanced = write_scene(
        &dir,
        "unbalanced.toml",
        r#"dofs = ["a", "b"]
mass = [[1.0, 0.0], [0.0, 1.0]]
damping = [[0.1, -0.1], [-0.1, 0.1]]
stiffness = [[1.0, -1.0], [-1.0, 1.0]]
fundamental = { rad_s = 1.2 }
harmonics = { count = 4 }
loads = [{ dof = "a", order = 0, cos = 1.0 }, { dof = "a", order = 1, cos = 0.1 }]
"#,
    );
    for (scene, what) in [
        (&h0, "only 0 harmonics are kept"),
        (&unbalanced, "the static loads do not balance"),
    ] {
        let solve = hbal(&["solve", scene, "--json"]);
        let sweep = hbal(&["sweep", scene, "--to", "1.5", "--json"]);
        for (name, out) in [("solve", &solve), ("sweep", &sweep)] {
            assert_eq!(
                out.status.code(),
                Some(2),
                "{name} {scene}: {}",
                stderr(out)
            );
            assert!(stderr(out).contains(what), "{name}: {}", stderr(out));
            assert!(out.stdout.is_empty(), "{name}");
        }
    }
}

/// A start file whose harmonics would overflow the residual is bad input (exit 2, named),
/// not a numerical failure with nothing on stdout.
#[test]
fn a_start_that_would_overflow_is_bad_input() {
    let dir = temp_dir("options_contract_start");
    let out = hbal(&["solve", TWO_SHAFT, "--json"]);
    let mut doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    doc["dofs"][0]["harmonics"][1]["cos"] = serde_json::json!(1e300);
    let start = dir.join("start.json");
    std::fs::write(&start, doc.to_string()).unwrap();
    let out = hbal(&[
        "solve",
        TWO_SHAFT,
        "--start",
        start.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("harmonic 1 of `gear` is 1.000e300"),
        "{}",
        stderr(&out)
    );
    assert!(out.stdout.is_empty());
}

/// Where the operating point or every method fails to converge, `modes --json` and
/// `compare --json` still print their one document, marked, and say so on stderr (exit 1).
#[test]
fn unconverged_modes_and_compare_print_a_marked_document_and_an_error() {
    let backlash = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/gear_backlash.toml"
    );
    for command in ["modes", "compare"] {
        let out = hbal(&[command, backlash, "--method", "fixed_point", "--json"]);
        assert_eq!(out.status.code(), Some(1), "{command}: {}", stderr(&out));
        let doc: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{command}: {e}"));
        let converged = match command {
            "modes" => doc["converged"].clone(),
            _ => doc["methods"][0]["converged"].clone(),
        };
        assert_eq!(converged, serde_json::json!(false), "{command}: {doc}");
        assert!(
            stderr(&out).contains("error:"),
            "{command}: {}",
            stderr(&out)
        );
    }
}

/// `hbal check` accepts what `hbal solve` accepts: automatic harmonics whose first count is
/// below a mesh order (the solve raises H to the orders first; check refused it with exit 2).
#[test]
fn check_accepts_automatic_harmonics_below_the_mesh_order() {
    let dir = temp_dir("options_contract_check");
    let scene = write_scene(
        &dir,
        "auto.toml",
        r#"dofs = ["x"]
mass = [[1.0]]
damping = [[0.1]]
fundamental = { rad_s = 0.7 }
harmonics = { count = 2, auto = true }
loads = [{ dof = "x", order = 0, cos = 0.1 }, { dof = "x", order = 1, cos = 0.05 }]

[[elements]]
name = "contact"
type = "backlash"
connects = { x = 1.0 }
half_backlash = 1.0
teeth = 5
stiffness = { shape = "cosine", mean = 1.0, amplitude = 0.2 }
"#,
    );
    for command in ["check", "solve"] {
        let out = hbal(&[command, &scene]);
        assert_eq!(out.status.code(), Some(0), "{command}: {}", stderr(&out));
    }
    // Below the orders with a cap that cannot reach them: both refuse.
    let capped = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("auto = true", "auto = true, max = 4");
    let capped = write_scene(&dir, "capped.toml", &capped);
    for command in ["check", "solve"] {
        let out = hbal(&[command, &capped]);
        assert_eq!(out.status.code(), Some(2), "{command}: {}", stderr(&out));
        assert!(stderr(&out).contains(">= 5"), "{command}: {}", stderr(&out));
    }
}

/// Messages say what is wrong in the user's terms: an unknown field is unknown (not "out of
/// range" because of its value), a whole-number field given 1e300 asks for a whole number, and
/// a control character echoed from the input is escaped, not sent to the terminal.
#[test]
fn messages_name_the_problem_and_escape_control_characters() {
    let dir = temp_dir("options_contract_messages");
    let duffing = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/duffing.toml"
    ))
    .unwrap();
    let unknown = write_scene(&dir, "unknown.toml", &format!("foo = 1e300\n{duffing}"));
    let whole = write_scene(
        &dir,
        "whole.toml",
        &duffing.replace("harmonics = { count = 7 }", "harmonics = { count = 1e300 }"),
    );
    let huge = write_scene(&dir, "huge.toml", &duffing.replace("k = 1.0", "k = 1e300"));
    for (scene, want) in [
        (&unknown, "unknown field `foo`"),
        (
            &whole,
            "harmonics.count: invalid type: floating point `1e+300`, expected a whole number >= 0",
        ),
        (
            &huge,
            "elements[0].k: must be 0 or between 1e-100 and 1e100 in magnitude",
        ),
    ] {
        let out = hbal(&["solve", scene]);
        assert_eq!(out.status.code(), Some(2), "{scene}");
        assert!(stderr(&out).contains(want), "{scene}: {}", stderr(&out));
    }
    let valid = write_scene(&dir, "valid.toml", &duffing);
    let out = hbal(&["solve", &valid, "--method", "ne\u{1b}[31mw"]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(!err.contains('\u{1b}'), "{err:?}");
    assert!(err.contains("ne\\u{1b}[31mw"), "{err}");
}

/// A file the scene names that never ends (`/dev/zero`) is refused at the size bound, exit 2,
/// instead of read until memory runs out.
#[cfg(unix)]
#[test]
fn an_endless_file_is_refused_at_the_size_bound() {
    let dir = temp_dir("options_contract_endless");
    let scene = write_scene(
        &dir,
        "endless.toml",
        "dofs = { file = \"/dev/zero\" }\nmass = [[1.0]]\nfundamental = { rad_s = 1.0 }\nharmonics = { count = 2 }\n",
    );
    for args in [vec!["solve", scene.as_str()], vec!["solve", "/dev/zero"]] {
        let out = hbal(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("larger than the limit of 256 MiB"),
            "{args:?}: {}",
            stderr(&out)
        );
    }
}

/// The start check refuses only what a sweep would refuse: a linear time-invariant scene
/// above the dense-Jacobian size is swept by one solve per harmonic and needs no Jacobian
/// (found by review: 1 DOF at H = 4100 was refused with exit 2).
#[test]
fn a_large_linear_sweep_is_not_refused_for_a_jacobian_it_does_not_need() {
    let dir = temp_dir("options_contract_lti");
    let scene = write_scene(
        &dir,
        "lti.toml",
        r#"dofs = ["x"]
mass = [[1.0]]
damping = [[0.02]]
stiffness = [[1.0]]
fundamental = { rad_s = 0.5 }
harmonics = { count = 4100 }
loads = [{ dof = "x", order = 1, cos = 0.1 }]
"#,
    );
    let out = hbal(&["sweep", &scene, "--to", "0.6", "--no-stability"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
}

/// A directory where a subcommand writes a file (harmonics.csv, branch.csv, campbell.svg,
/// report.html, ...) is bad input found before any work: exit 2, nothing on stdout, the path
/// named, no other file written.
#[test]
fn an_output_file_blocked_by_a_directory_is_refused_before_any_work() {
    let duffing = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/duffing.toml");
    let cases: [(&[&str], &str); 7] = [
        (&["solve", "--json", duffing], "harmonics.csv"),
        (&["solve", duffing], "not_converged_spectrum.svg"),
        (&["sweep", "--json", "--to", "1.3", duffing], "branch.csv"),
        (
            &["sweep", "--to", "1.3", duffing],
            "frequency_response_x.svg",
        ),
        (&["modes", "--json", duffing], "campbell.svg"),
        (&["compare", duffing], "residual_histories.svg"),
        (&["report", TWO_SHAFT, "--to", "7000"], "report.html"),
    ];
    for (i, (args, blocked)) in cases.iter().enumerate() {
        let dir = temp_dir(&format!("options_contract_blocked_{i}"));
        let out_dir = dir.join("out");
        std::fs::create_dir_all(out_dir.join(blocked)).unwrap();
        let mut all: Vec<&str> = args.to_vec();
        all.extend(["--out", out_dir.to_str().unwrap()]);
        let out = hbal(&all);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            out.stdout.is_empty(),
            "{args:?} printed {}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(
            err.contains(&format!("{blocked} is a directory")),
            "{args:?}: {err}"
        );
        let written: Vec<_> = std::fs::read_dir(&out_dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .filter(|n| n != blocked && !["solve", "sweep", "modes"].contains(&n.as_str()))
            .collect();
        assert!(written.is_empty(), "{args:?} wrote {written:?}");
    }
    // A report's part folder: a file where `solve/` goes.
    let dir = temp_dir("options_contract_blocked_folder");
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    std::fs::write(out_dir.join("solve"), "").unwrap();
    let out = hbal(&["report", TWO_SHAFT, "--out", out_dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!out_dir.join("report.html").exists());
}

/// The library's own checks of a sweep (an unknown `--output`, a parameter sweep's `--method`)
/// run before `--out` is prepared: no directory is left behind.
#[test]
fn a_sweep_refused_by_the_library_leaves_no_out_directory() {
    let duffing = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/duffing.toml");
    let dir = temp_dir("options_contract_sweep_out");
    let out_dir = dir.join("out");
    let out_arg = out_dir.to_str().unwrap();
    for args in [
        vec![
            "sweep", duffing, "--to", "2", "--output", "nope", "--out", out_arg,
        ],
        vec![
            "sweep",
            duffing,
            "--parameter",
            "loads[0].cos",
            "--from",
            "0",
            "--to",
            "1",
            "--method",
            "newton",
            "--out",
            out_arg,
        ],
        vec![
            "sweep",
            duffing,
            "--parameter",
            "dofs.count",
            "--from",
            "1",
            "--to",
            "2",
            "--out",
            out_arg,
        ],
    ] {
        let out = hbal(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(!out_dir.exists(), "{args:?} created {}", out_dir.display());
    }
}
