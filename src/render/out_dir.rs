//! The output directory (`--out DIR`, Python's `out=`), checked before any work: it can be
//! created and written, none of the files an analysis writes there is a directory or
//! read-only, and every DOF or element name that becomes part of a file name stays a file
//! name inside it.

use crate::error::{Error, Result};
use std::path::Path;

/// Makes `dir` ready before any work: creates it, writes and removes a probe file, and checks
/// that none of `files` (the names an analysis writes there) is a directory or a file it
/// cannot write, so that an unusable directory is bad input (exit code 2, nothing written)
/// instead of a failure after the run.
///
/// ```
/// let dir = std::env::temp_dir().join(format!("hbal-doc-out-{}", std::process::id()));
/// hbal::render::prepare_out(&dir, &hbal::render::solve_files()).unwrap();
/// std::fs::create_dir_all(dir.join("spectrum.svg")).unwrap();
/// let e = hbal::render::prepare_out(&dir, &hbal::render::solve_files()).unwrap_err();
/// assert!(e.to_string().contains("is a directory where hbal writes a file"));
/// assert_eq!(e.exit_code(), 2);
/// std::fs::remove_dir_all(&dir).unwrap();
/// ```
pub fn prepare_out(dir: &Path, files: &[String]) -> Result<()> {
    let shown = dir.display();
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::Output(format!("--out {shown}: cannot create the directory: {e}")))?;
    let probe = dir.join(".hbal_write_test");
    std::fs::write(&probe, b"").map_err(|e| {
        Error::Output(format!(
            "--out {shown}: cannot write into the directory: {e}"
        ))
    })?;
    let _ = std::fs::remove_file(probe);
    for name in files {
        let path = dir.join(name);
        let Ok(meta) = std::fs::metadata(&path) else {
            continue;
        };
        if meta.is_dir() {
            return Err(Error::Output(format!(
                "--out {shown}: {} is a directory where hbal writes a file: move it or choose another --out",
                path.display()
            )));
        }
        std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| {
                Error::Output(format!(
                    "--out {shown}: cannot write {}: {e}",
                    path.display()
                ))
            })?;
    }
    Ok(())
}

/// The files a solve writes (those of a converged solve and of an unconverged iterate).
pub fn solve_files() -> Vec<String> {
    let names = [
        "harmonics.csv",
        "time_series.csv",
        "elements.csv",
        "time_series.svg",
        "spectrum.svg",
    ];
    let prefixed = names.iter().map(|n| format!("not_converged_{n}"));
    names
        .iter()
        .map(|n| n.to_string())
        .chain(prefixed)
        .collect()
}

/// The files a sweep writes besides the switched branches' (`branch_1.csv`, ...): the
/// branch, the order cuts and one frequency response per reported DOF of `dofs`.
pub fn sweep_files<'a>(dofs: impl Iterator<Item = &'a String>) -> Vec<String> {
    let names = [
        "branch.csv",
        "order_cuts.csv",
        "order_cuts.svg",
        "waterfall.svg",
    ];
    let plots = dofs.map(|d| format!("frequency_response_{d}.svg"));
    names.iter().map(|n| n.to_string()).chain(plots).collect()
}

/// Makes `dir` ready for a speed sweep of `scene` reporting the DOFs `dofs` (a selection as
/// [`crate::analysis::reported_dofs`] reads it, by default every DOF of a small model): every
/// DOF name can be part of a file name, and [`prepare_out`] with [`sweep_files`].
pub fn prepare_sweep_out(
    dir: &Path,
    scene: &crate::scene::Scene,
    dofs: Option<&str>,
) -> Result<()> {
    let names = scene.model.dof_names();
    for dof in names {
        file_name_part(dof, "DOF")?;
    }
    let reported = crate::analysis::reported_dofs(&scene.model, dofs)?;
    prepare_out(dir, &sweep_files(reported.iter().map(|&i| &names[i])))
}

/// The files the natural frequencies write.
pub fn modes_files() -> Vec<String> {
    vec!["modes.csv".into(), "campbell.svg".into()]
}

/// The files a solve on several base frequencies writes.
pub fn torus_solve_files() -> Vec<String> {
    vec!["lines.csv".into(), "spectrum.svg".into()]
}

/// The files a sweep on several base frequencies writes.
pub fn torus_sweep_files() -> Vec<String> {
    [
        "points.csv",
        "order_cuts.csv",
        "order_cuts.svg",
        "waterfall.svg",
    ]
    .map(String::from)
    .to_vec()
}

/// Checks that `name` (of a DOF or an element, `what`) can be part of a file name in the
/// output directory: no path separators, no control characters, not empty, not `.` or `..`;
/// nothing is written outside it.
///
/// ```
/// use hbal::render::file_name_part;
/// assert!(file_name_part("gear", "DOF").is_ok());
/// assert!(file_name_part("../gear", "DOF").is_err());
/// ```
pub fn file_name_part(name: &str, what: &str) -> Result<()> {
    let bad = name.is_empty()
        || name == "."
        || name == ".."
        || name
            .chars()
            .any(|c| c == '/' || c == '\\' || c == ':' || c.is_control());
    if bad {
        return Err(Error::Output(format!(
            "{what} `{}` cannot be part of a file name in --out (no `/`, `\\`, `:`, control characters, `.` or `..`): rename it",
            name.escape_debug()
        )));
    }
    Ok(())
}
