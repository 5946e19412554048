//! Automatic harmonics in the commands beyond `solve` and the speed sweep: `hbal compare` runs
//! every method at the H they choose, `hbal sweep --parameter` chooses H at the first value and
//! keeps it (before, both ran at the scene's count and said nothing).

use crate::common::hbal;
use std::path::{Path, PathBuf};

/// The paper's two-shaft model at 6000 rpm with `count = 8` and `extra` in its harmonics table,
/// written to a scratch directory (removed when dropped): automatic harmonics on the harmonics
/// 0..H go 8 -> 16 -> 32 to reach 1e-6.
struct Scratch(PathBuf);

impl Scratch {
    fn two_shaft_at_h8(tag: &str, extra: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("hbal-auto-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/two_shaft_6000rpm.toml"),
        )
        .unwrap()
        .replace(
            "[harmonics]\ncount = 32\n",
            &format!("[harmonics]\ncount = 8\n{extra}"),
        );
        assert!(text.contains("count = 8"));
        std::fs::write(dir.join("two_shaft.toml"), text).unwrap();
        Self(dir)
    }

    fn scene(&self) -> PathBuf {
        self.0.join("two_shaft.toml")
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn compare_runs_every_method_at_the_automatic_h() {
    let scratch = Scratch::two_shaft_at_h8("compare", "");
    let p = scratch.scene();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "compare",
            p.to_str().unwrap(),
            "--method",
            "newton",
            "--json",
        ];
        args.extend(extra);
        let out = hbal(&args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let error = doc["methods"][0]["error_vs_time_domain"].as_f64().unwrap();
        (doc["harmonics"].as_u64().unwrap(), error, out.stderr)
    };
    // The scene's H = 8: the harmonics are off by far more than 1e-6.
    let (h, error, _) = run(&[]);
    assert_eq!(h, 8);
    assert!(error > 1e-4, "{error}");
    // Automatic harmonics on the harmonics 0..H: H = 32, and the time domain confirms 1e-6
    // (8.9e-7 against the exact solution).
    let (h, error, stderr) = run(&["--harmonics", "auto:harmonics"]);
    assert_eq!(h, 32);
    assert!(error <= 1e-6, "{error}");
    let note = String::from_utf8_lossy(&stderr);
    assert!(note.contains("every method at H = 32"), "{note}");
}

#[test]
fn a_parameter_sweep_keeps_the_h_chosen_at_its_first_value() {
    let plain = Scratch::two_shaft_at_h8("parameter", "");
    let automatic =
        Scratch::two_shaft_at_h8("parameter-auto", "auto = true\ncontrol = \"harmonics\"\n");
    let run = |p: &Path, extra: &[&str]| {
        let mut args = vec![
            "sweep",
            p.to_str().unwrap(),
            "--parameter",
            "loads[0].cos",
            "--from",
            "10",
            "--to",
            "12",
            "--points",
            "3",
            "--no-stability",
            "--json",
        ];
        args.extend(extra);
        let out = hbal(&args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(doc["points"].as_array().unwrap().len(), 3);
        (doc["harmonics"].as_u64().unwrap(), out.stderr)
    };
    assert_eq!(run(&plain.scene(), &[]).0, 8);
    let (h, stderr) = run(&plain.scene(), &["--harmonics", "auto:harmonics"]);
    assert_eq!(h, 32);
    let note = String::from_utf8_lossy(&stderr);
    assert!(
        note.contains("H = 32") && note.contains("not checked at the others"),
        "{note}"
    );
    // The scene's automatic harmonics, and a fixed --harmonics over them.
    assert_eq!(run(&automatic.scene(), &[]).0, 32);
    assert_eq!(run(&automatic.scene(), &["--harmonics", "8"]).0, 8);
}
