//! `--start FILE`: a previous `hbal solve --json` result as the initial guess of `solve` or
//! `sweep`, read by [`hbal::analysis::start_from_record`]. A file that does not fit the scene
//! is bad input (exit code 2).

use super::Failure;
use hbal::analysis::StartRecord;
use hbal::scene::Scene;
use serde_json::Value;
use std::path::Path;

/// Reads `path` (the JSON of `hbal solve --json`) for `scene`.
pub(crate) fn read(path: &Path, scene: &Scene) -> Result<StartRecord, Failure> {
    let file = path.display().to_string();
    let bad = |msg: String| -> Failure {
        anyhow::anyhow!("--start {file}: {msg} (expected the output of `hbal solve --json`)").into()
    };
    let text = hbal::scene::bounded_read::read_text(path)
        .map_err(|e| Failure::from(anyhow::anyhow!("--start {file}: cannot read the file: {e}")))?;
    let doc: Value =
        serde_json::from_str(&text).map_err(|e| bad(format!("not a JSON object: {e}")))?;
    hbal::analysis::start_from_record(&doc, scene).map_err(bad)
}
