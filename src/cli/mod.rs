//! The `hbal` command line: [`main`] runs it, in hbal's own binary or in a user's crate with
//! force laws of its own (a law registered with `#[typetag::serde(name = "...")]` is a scene
//! `type` like the built-ins; see `examples/custom_law_cli.rs`):
//!
//! ```no_run
//! fn main() -> std::process::ExitCode {
//!     hbal::cli::main()
//! }
//! ```
//!
//! Exit codes: 0 success, 1 a numerical failure: a solve that did not converge, a branch that
//! stopped before `--to`, a failed stability computation (the partial result is still reported
//! and written), 2 bad input (the message names the file and the field).
//!
//! Below: the subcommands' flags (`command.rs`) and one file per subcommand; shared here: the
//! `say!` macro, the `Failure` error with its exit code, the solver overrides shared by
//! `solve`, `compare` and `sweep` (`--method`, `--harmonics`, `--samples`, `--tolerance`) and
//! scene loading with them.

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
mod command;
pub(crate) mod compare;
pub(crate) mod dof_selection;
pub(crate) mod element_report;
pub(crate) mod modes;
pub(crate) mod parameter_sweep;
pub(crate) mod progress;
mod quantity_report;
pub(crate) mod report;
pub(crate) mod solve;
mod solve_text;
pub(crate) mod start;
pub(crate) mod sweep;
pub(crate) mod sweep_command;
pub(crate) mod sweep_summary;
mod sweep_text;
pub(crate) mod torus_solve;
pub(crate) mod torus_sweep;

/// Runs the `hbal` command line on the process's arguments (`hbal solve SCENE`, `sweep`,
/// `report`, ...) and returns its exit code. A panic is one line on stderr, not a backtrace.
pub fn main() -> std::process::ExitCode {
    // A bug must not greet a user with a backtrace: one line, and where to report it.
    std::panic::set_hook(Box::new(|info| {
        eprintln!("error: internal error in hbal ({info}); please report it with the scene file");
    }));
    command::run()
}

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

/// The warnings of a rendering (plots that could not be drawn: the computation and its CSV
/// files stand, and the exit code stays the computation's).
pub(crate) fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
}

/// A library error with the scene's name and its exit code ([`exit_code`]).
pub(crate) fn failure(e: hbal::Error, file: &str) -> Failure {
    let code = exit_code(&e);
    // A scene error names its file already.
    // A scene error names its file already; an output error is about the output.
    let named = matches!(&e, hbal::Error::Scene(s) if s.file == file)
        || matches!(&e, hbal::Error::Output(_));
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

pub(crate) use hbal::render::speed_text;
