//! Shared pieces of the `hbal` subcommands: the `say!` macro, the `Failure` error with its
//! exit code, the solver overrides shared by `solve`, `compare` and `sweep` (`--method`,
//! `--harmonics`, `--samples`, `--tolerance`) and scene loading with them, and the JSON of
//! Floquet multipliers. Each subcommand lives in its own file below.

use anyhow::Context;
use hbal::scene::Scene;
use std::path::Path;

/// `println!` that ends the process quietly when stdout is closed (`hbal ... | head`).
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout(), $($t)*) {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                std::process::exit(0);
            }
        }
    }};
}

pub(crate) mod check;
pub(crate) mod compare;
pub(crate) mod dof_selection;
pub(crate) mod element_report;
pub(crate) mod modes;
pub(crate) mod order_cuts;
pub(crate) mod parameter_sweep;
pub(crate) mod progress;
mod quantity_report;
pub(crate) mod report;
pub(crate) mod report_html;
pub(crate) mod solve;
pub(crate) mod solve_exact;
mod solve_files;
mod solve_text;
pub(crate) mod start;
pub(crate) mod sweep;
pub(crate) mod sweep_command;
mod sweep_files;
pub(crate) mod sweep_summary;
mod sweep_text;
pub(crate) mod torus_report;
pub(crate) mod torus_solve;
pub(crate) mod torus_sweep;

/// An error with its exit code.
pub(crate) struct Failure {
    pub(crate) code: u8,
    pub(crate) error: anyhow::Error,
}

impl<E: Into<anyhow::Error>> From<E> for Failure {
    fn from(e: E) -> Self {
        Failure {
            code: 2,
            error: e.into(),
        }
    }
}

/// Exit code of a library error ([`hbal::Error::exit_code`]).
pub(crate) fn exit_code(e: &hbal::Error) -> u8 {
    e.exit_code()
}

/// A plot that cannot be drawn (nothing finite to show) is a warning on stderr: the
/// computation and its CSV files stand, and the exit code stays the computation's.
pub(crate) fn plot_warning(e: Box<dyn std::error::Error>) {
    eprintln!("warning: plot: {e}");
}

/// A library error with the scene's name and its exit code ([`exit_code`]).
pub(crate) fn failure(e: hbal::Error, file: &str) -> Failure {
    let code = exit_code(&e);
    // A scene error names its file already.
    let named = matches!(&e, hbal::Error::Scene(s) if s.file == file);
    let error = anyhow::Error::new(e);
    Failure {
        code,
        error: if named {
            error
        } else {
            error.context(file.to_string())
        },
    }
}

/// The solver overrides of `solve`, `compare` and `sweep`.
#[derive(clap::Args, Debug, Clone, Default)]
pub(crate) struct SolverArgs {
    /// Solver: fixed_point, newton, broyden, anderson, or piecewise_exact (the exact solution of a linear scene with piecewise-constant coefficients) (default: the scene's).
    #[arg(long)]
    pub(crate) method: Option<String>,
    /// Number of harmonics H, or `auto` to raise H until the estimated error is below the
    /// scene's `harmonics.tolerance` (default 1e-6) (default: the scene's). `auto:harmonics`
    /// controls the error of the harmonics 0..H alone (order amplitudes), `auto:quantities`
    /// that of every DOF and element coordinate on its own (dynamic part against its own
    /// range, peak values included; the default), `auto:solution` that of the periodic
    /// solution as a whole with the harmonics it lacks.
    #[arg(long)]
    pub(crate) harmonics: Option<hbal::scene::HarmonicsOverride>,
    /// Number of time samples N per period, at least 2H+1 (default: the scene's, or the
    /// default for --harmonics).
    #[arg(long)]
    pub(crate) samples: Option<usize>,
    /// Relative residual tolerance of the solver, in [1e-15, 1) (default: the scene's).
    #[arg(long, allow_negative_numbers = true)]
    pub(crate) tolerance: Option<f64>,
    /// Unknowns: `full` (all DOFs per harmonic), `condensed` (the element coordinates,
    /// exact; for large models), or `auto` (condensed where it pays).
    #[arg(long, default_value = "auto")]
    pub(crate) formulation: hbal::Formulation,
}

impl SolverArgs {
    /// The library's overrides of these flags.
    pub(crate) fn overrides(&self) -> hbal::scene::Overrides {
        hbal::scene::Overrides {
            method: self.method.clone(),
            harmonics: self.harmonics,
            samples: self.samples,
            tolerance: self.tolerance,
            formulation: self.formulation,
        }
    }
}

/// Loads the scene and applies the command-line overrides.
pub(crate) fn load(path: &Path, args: &SolverArgs) -> Result<Scene, Failure> {
    let mut scene = Scene::load(path)?;
    for note in &scene.notes {
        eprintln!("note: {}: {note}", scene.file);
    }
    args.overrides()
        .apply(&mut scene)
        .map_err(|e| failure(e, &scene.file))?;
    Ok(scene)
}

/// `text` with its control characters (other than line breaks and tabs) written as `\u{1b}`
/// escapes: a scene's names or a command-line value echoed in a message cannot move the
/// terminal's cursor or colour it.
pub(crate) fn printable(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() && c != '\n' && c != '\t' {
                c.escape_unicode().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// A multiplier modulus for the text summaries: 6 decimals, or 4 significant digits under 1e-3.
pub(crate) fn modulus(x: f64) -> String {
    if x == 0.0 || x >= 1e-3 {
        format!("{x:.6}")
    } else {
        format!("{x:.3e}")
    }
}

/// A speed for titles: up to 6 significant digits, no trailing zeros (`2000`, `1.3455`).
pub(crate) fn speed_text(v: f64) -> String {
    let digits = if v == 0.0 || !v.is_finite() {
        0
    } else {
        (5 - v.abs().log10().floor() as i32).clamp(0, 12) as usize
    };
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Makes `--out DIR` ready before any work: creates it, writes and removes a probe file, and
/// checks that none of `files` (the names the subcommand writes there) is a directory or a
/// file it cannot write, so that an unusable directory is bad input (exit 2, nothing written)
/// instead of a failure after the run.
pub(crate) fn prepare_out(dir: &Path, files: &[String]) -> Result<(), Failure> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("--out {}: cannot create the directory", dir.display()))?;
    let probe = dir.join(".hbal_write_test");
    std::fs::write(&probe, b"")
        .with_context(|| format!("--out {}: cannot write into the directory", dir.display()))?;
    let _ = std::fs::remove_file(probe);
    for name in files {
        let path = dir.join(name);
        let Ok(meta) = std::fs::metadata(&path) else {
            continue;
        };
        if meta.is_dir() {
            return Err(anyhow::anyhow!(
                "--out {}: {} is a directory where hbal writes a file: move it or choose another --out",
                dir.display(),
                path.display()
            )
            .into());
        }
        std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .with_context(|| format!("--out {}: cannot write {}", dir.display(), path.display()))?;
    }
    Ok(())
}

/// The files `hbal solve --out` writes (those of a converged solve and of an unconverged
/// iterate).
pub(crate) fn solve_files() -> Vec<String> {
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

/// The files `hbal sweep --out` writes besides the switched branches' (`branch_1.csv`, ...):
/// the branch, the order cuts and one frequency response per reported DOF of `dofs`.
pub(crate) fn sweep_files<'a>(dofs: impl Iterator<Item = &'a String>) -> Vec<String> {
    let names = [
        "branch.csv",
        "order_cuts.csv",
        "order_cuts.svg",
        "waterfall.svg",
    ];
    let plots = dofs.map(|d| format!("frequency_response_{d}.svg"));
    names.iter().map(|n| n.to_string()).chain(plots).collect()
}

/// The files `hbal modes --out` writes.
pub(crate) fn modes_files() -> Vec<String> {
    vec!["modes.csv".into(), "campbell.svg".into()]
}

/// Checks that `name` (of a DOF or an element, `what`) can be part of a file name in `--out`:
/// no path separators, no control characters, not empty, not `.` or `..`; nothing is written
/// outside `--out`.
///
/// ```ignore
/// assert!(file_name_part("gear", "DOF").is_ok());
/// assert!(file_name_part("../gear", "DOF").is_err());
/// ```
pub(crate) fn file_name_part(name: &str, what: &str) -> Result<(), Failure> {
    let bad = name.is_empty()
        || name == "."
        || name == ".."
        || name
            .chars()
            .any(|c| c == '/' || c == '\\' || c == ':' || c.is_control());
    if bad {
        return Err(anyhow::anyhow!(
            "{what} `{}` cannot be part of a file name in --out (no `/`, `\\`, `:`, control characters, `.` or `..`): rename it",
            name.escape_debug()
        )
        .into());
    }
    Ok(())
}
