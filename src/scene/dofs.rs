//! The scene's `dofs`: a list of names, a sidecar file with one name per line, or generated
//! names.
//!
//! ```toml
//! dofs = ["x1", "x2"]                        # the names
//! dofs = { file = "dofs.txt" }               # one per line; blank lines and `#` comments ignored
//! dofs = { count = 1000, prefix = "shaft" }  # shaft.1 ... shaft.1000 (prefix default `dof`)
//! dofs = { count = 4, first = 0 }            # dof.0 ... dof.3, numbered from 0 as
//!                                            # openTorsion and most shaft-line tools do
//! ```
//!
//! A sidecar file's path is relative to the scene file's directory.

use serde::Deserialize;
use serde_json::Value;
use std::path::Path;

/// The DOF names and, if they did not come from an inline list, where from (for messages).
#[derive(Debug, Clone)]
pub(super) struct Dofs {
    /// The names, in order.
    pub(super) names: Vec<String>,
    /// `dofs.txt` (the resolved path) or `dofs.count`; `None` for an inline list.
    pub(super) origin: Option<String>,
}

impl Dofs {
    /// `" (from dofs.txt)"`, or nothing for an inline list.
    pub(super) fn origin_note(&self) -> String {
        self.origin
            .as_ref()
            .map_or(String::new(), |o| format!(" (from {o})"))
    }

    /// The names for a message: all of them, or the first few and the count.
    pub(super) fn listing(&self) -> String {
        const SHOWN: usize = 8;
        if self.names.len() <= SHOWN {
            self.names.join(", ")
        } else {
            format!(
                "{}, ... ({} in all{})",
                self.names[..SHOWN].join(", "),
                self.names.len(),
                self.origin_note()
            )
        }
    }
}

/// `dofs = { file = ... }` or `dofs = { count = ..., prefix = ... }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DofSource {
    file: Option<String>,
    count: Option<usize>,
    prefix: Option<String>,
    /// The number of the first generated name: 1 (default) or 0.
    first: Option<u64>,
}

/// Reads the `dofs` field; errors are `(field path, message)`.
pub(super) fn read(value: &Value, base: &Path) -> Result<Dofs, (String, String)> {
    let e = |path: &str, message: String| (path.to_string(), message);
    let dofs = match value {
        Value::Object(_) => {
            let source: DofSource = serde_path_to_error::deserialize(value).map_err(|x| {
                let path = x.path().to_string();
                let message = x.into_inner().to_string();
                let path = super::field_path(path, &message);
                let path = if path == "." {
                    "dofs".to_string()
                } else {
                    format!("dofs.{path}")
                };
                (path, message)
            })?;
            match source {
                DofSource {
                    file: Some(file),
                    count: None,
                    prefix: None,
                    first: None,
                } => sidecar(&base.join(file)).map_err(|m| e("dofs.file", m))?,
                DofSource {
                    file: None,
                    count: Some(count),
                    prefix,
                    first,
                } => {
                    if count > crate::Model::MAX_DOFS {
                        return Err(e(
                            "dofs.count",
                            format!(
                                "must be at most {} (the largest model), got {count}",
                                crate::Model::MAX_DOFS
                            ),
                        ));
                    }
                    let prefix = prefix.unwrap_or_else(|| "dof".to_string());
                    if prefix.trim().is_empty() {
                        return Err(e("dofs.prefix", "must not be empty".into()));
                    }
                    let first = match first {
                        None => 1,
                        Some(f @ (0 | 1)) => f as usize,
                        Some(f) => {
                            return Err(e(
                                "dofs.first",
                                format!("must be 0 or 1 (the number of the first name), got {f}"),
                            ))
                        }
                    };
                    Dofs {
                        names: (first..first + count)
                            .map(|i| format!("{prefix}.{i}"))
                            .collect(),
                        origin: Some("dofs.count".into()),
                    }
                }
                DofSource {
                    file: Some(_),
                    prefix: Some(_),
                    ..
                } => {
                    return Err(e(
                        "dofs.prefix",
                        "applies to `count` only, not to a `file`".into(),
                    ))
                }
                DofSource {
                    file: Some(_),
                    first: Some(_),
                    ..
                } => {
                    return Err(e(
                        "dofs.first",
                        "applies to `count` only, not to a `file`".into(),
                    ))
                }
                _ => {
                    return Err(e(
                        "dofs",
                        "give a list of names, `{ file = \"dofs.txt\" }` (one name per line) \
                         or `{ count = 1000, prefix = \"shaft\" }`"
                            .into(),
                    ))
                }
            }
        }
        _ => {
            let names: Vec<String> = serde_path_to_error::deserialize(value).map_err(|x| {
                let path = x.path().to_string();
                let path = if path == "." {
                    "dofs".into()
                } else {
                    format!("dofs{path}")
                };
                (path, x.into_inner().to_string())
            })?;
            let mut first = std::collections::HashMap::new();
            for (i, name) in names.iter().enumerate() {
                if let Some(j) = first.insert(name.as_str(), i) {
                    return Err(e(
                        &format!("dofs[{i}]"),
                        format!(
                            "DOF `{name}` appears twice (first at dofs[{j}]): names are unique"
                        ),
                    ));
                }
            }
            Dofs {
                names,
                origin: None,
            }
        }
    };
    if dofs.names.is_empty() {
        return Err(match dofs.origin.as_deref() {
            None => e("dofs", "at least one DOF is required".into()),
            Some("dofs.count") => e("dofs.count", "at least one DOF is required".into()),
            Some(_) => e(
                "dofs.file",
                format!("at least one DOF is required{}", dofs.origin_note()),
            ),
        });
    }
    Ok(dofs)
}

/// A sidecar list: one name per line, `#` starts a comment, blank lines are skipped, no name
/// twice.
fn sidecar(path: &Path) -> Result<Dofs, String> {
    let file = path.display().to_string();
    let text = super::bounded_read::read_text(path)
        .map_err(|e| format!("{file}: cannot read the DOF list: {e}"))?;
    let mut names: Vec<String> = Vec::new();
    let mut first_line = std::collections::HashMap::new();
    for (n, line) in text.lines().enumerate() {
        let name = line.split('#').next().unwrap_or("").trim();
        if name.is_empty() {
            continue;
        }
        if let Some(first) = first_line.insert(name.to_string(), n + 1) {
            return Err(format!(
                "{file}:{}: DOF `{name}` appears twice (first on line {first})",
                n + 1
            ));
        }
        names.push(name.to_string());
    }
    Ok(Dofs {
        names,
        origin: Some(file),
    })
}
