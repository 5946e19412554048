//! The subcommands and their flags (clap), and the dispatch to their files.

use crate::cli;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "hbal",
    version,
    about = "Harmonic balance for powertrains: periodic steady state of gear meshes, backlash and user force laws"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a scene: summary with Floquet stability, CSV of harmonics and time series, SVG plots.
    Solve {
        /// Scene file (.toml or .json).
        scene: PathBuf,
        #[command(flatten)]
        solver: cli::SolverArgs,
        /// Start from a previous `hbal solve --json` result instead of the linear solution.
        #[arg(long, value_name = "FILE")]
        start: Option<PathBuf>,
        /// Skip the Floquet stability of the converged orbit.
        #[arg(long)]
        no_stability: bool,
        /// The scene's method alone, its result reported converged or not (exit code 1): no
        /// fallback to the other solvers, the load homotopy or continuation in the speed.
        #[arg(long)]
        no_fallback: bool,
        /// Print exactly one JSON object on stdout instead of the summary.
        #[arg(long)]
        json: bool,
        /// Write harmonics.csv, time_series.csv and SVG plots into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Every solver (or the one of --method) and the time-domain reference on one scene.
    Compare {
        /// Scene file (.toml or .json).
        scene: PathBuf,
        #[command(flatten)]
        solver: cli::SolverArgs,
        /// Print exactly one JSON object on stdout instead of the table.
        #[arg(long)]
        json: bool,
        /// Write an SVG of the residual histories into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Follow the frequency response through turning points, with stability.
    ///
    /// --from and --to are in the scene's speed unit (rpm, hz or rad_s of `fundamental`).
    Sweep(cli::sweep_command::SweepCommand),
    /// Natural frequencies and mode shapes about the scene's periodic solution (with the
    /// one- and two-tooth bounds of mesh stiffnesses), critical speeds; Campbell diagram.
    ///
    /// --from and --to are in the scene's speed unit (default 0 to twice the scene's speed).
    Modes {
        /// Scene file (.toml or .json).
        scene: PathBuf,
        /// Lowest speed of the Campbell diagram.
        #[arg(long, allow_negative_numbers = true)]
        from: Option<f64>,
        /// Highest speed of the Campbell diagram.
        #[arg(long, allow_negative_numbers = true)]
        to: Option<f64>,
        /// Modes up to this frequency in Hz (default: every mode up to 300 DOFs, else 5000).
        #[arg(long, allow_negative_numbers = true)]
        max_hz: Option<f64>,
        #[command(flatten)]
        solver: cli::SolverArgs,
        /// Print exactly one JSON object on stdout instead of the table.
        #[arg(long)]
        json: bool,
        /// Write modes.csv and campbell.svg into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// One self-contained report.html: the solve at the scene's speed, with --to the run-up
    /// (order cuts, waterfall, frequency responses), natural frequencies and the Campbell
    /// diagram, the scene and its settings.
    ///
    /// --from and --to are in the scene's speed unit; the CSV files and plots stay in
    /// DIR/solve, DIR/sweep and DIR/modes.
    Report {
        /// Scene file (.toml or .json).
        scene: PathBuf,
        /// Start speed of the run-up (default: the scene's speed).
        #[arg(long, allow_negative_numbers = true)]
        from: Option<f64>,
        /// End speed of the run-up (no run-up without it).
        #[arg(long, allow_negative_numbers = true)]
        to: Option<f64>,
        /// The directory of report.html (created; checked writable before any work).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// The element or DOF of the run-up's order cuts and waterfall.
        #[arg(long, value_name = "NAME")]
        output: Option<String>,
        /// Skip the Floquet stability.
        #[arg(long)]
        no_stability: bool,
        /// The run-up's largest continuation step (scaled arclength; default 0.5; smaller
        /// gives more points).
        #[arg(long, allow_negative_numbers = true)]
        max_step: Option<f64>,
        /// Stop the run-up after this many points (default 2000).
        #[arg(long, value_parser = cli::sweep_command::sweep_points(1))]
        max_points: Option<usize>,
        /// Evenly spaced speeds of the run-up on several base frequencies (default 101) or
        /// with the exact piecewise method.
        #[arg(long, value_parser = cli::sweep_command::sweep_points(2))]
        points: Option<usize>,
        #[command(flatten)]
        solver: cli::SolverArgs,
    },
    /// Validate a scene without solving.
    Check {
        /// Scene file (.toml or .json).
        scene: PathBuf,
    },
}

/// Parses the process's arguments and runs the subcommand; its exit code.
pub(crate) fn run() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Solve {
            scene,
            solver,
            start,
            no_stability,
            no_fallback,
            json,
            out,
        } => cli::solve::solve(
            &scene,
            &solver,
            cli::solve::SolveOptions {
                start: start.as_deref(),
                stability: !no_stability,
                fallback: !no_fallback,
                json,
                out: out.as_deref(),
            },
        ),
        Command::Compare {
            scene,
            solver,
            json,
            out,
        } => cli::compare::compare(&scene, &solver, json, out.as_deref()),
        Command::Check { scene } => cli::check::check(&scene),
        Command::Report {
            scene,
            from,
            to,
            out,
            output,
            no_stability,
            max_step,
            max_points,
            points,
            solver,
        } => cli::report::report(
            &scene,
            &solver,
            cli::report::ReportOptions {
                from,
                to,
                stability: !no_stability,
                out: &out,
                output: output.as_deref(),
                resolution: (max_step, max_points, points),
            },
        ),
        Command::Modes {
            scene,
            from,
            to,
            max_hz,
            solver,
            json,
            out,
        } => cli::modes::modes(
            &scene,
            &solver,
            cli::modes::ModesOptions {
                from,
                to,
                max_hz,
                json,
                out: out.as_deref(),
            },
        ),
        Command::Sweep(command) => command.run(),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(f) => {
            eprintln!("error: {}", cli::printable(&format!("{:#}", f.error)));
            ExitCode::from(f.code)
        }
    }
}
