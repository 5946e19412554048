//! Shared by the examples: the output directory from `--out DIR` (default `out/`), created.

use std::path::PathBuf;

/// The directory given with `--out` (default `out`), created if needed.
pub fn out_dir() -> std::io::Result<PathBuf> {
    let args: Vec<String> = std::env::args().collect();
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("out"));
    std::fs::create_dir_all(&out)?;
    Ok(out)
}
