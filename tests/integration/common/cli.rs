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
