//! Helpers of the CLI tests: the example scenes, JSON on stdout, temporary directories.

use std::path::{Path, PathBuf};
use std::process::Output;

/// `examples/scenes`.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes")
}

/// The one JSON object on stdout.
pub fn json_of(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "one JSON object on stdout ({e}): {}\nstderr: {}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// A fresh directory `hbal-<tag>-<pid>` in the system's temporary directory.
pub fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hbal-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The backlash pair at W = 0.8, where Newton from the linear start finds the unstable middle
/// orbit.
pub fn backlash_at_08(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(scenes_dir().join("gear_backlash.toml")).unwrap();
    assert!(text.contains("rad_s = 0.7"));
    let path = dir.join("backlash_08.toml");
    std::fs::write(&path, text.replace("rad_s = 0.7", "rad_s = 0.8")).unwrap();
    path
}

/// `hbal check` of `text` (written to `dir/bad.toml`) fails with exit code 2 and a message
/// that names the field `path` (`path:`) and says `words`.
pub fn check_refuses(dir: &Path, text: &str, path: &str, words: &str) {
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text).unwrap();
    let out = super::hbal(&["check", &bad.to_string_lossy()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{path}: {err}");
    assert!(
        err.contains(&format!("{path}:")) && err.contains(words),
        "{path}: {err}"
    );
}
