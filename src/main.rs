//! The `hbal` command line: solve, compare and check scene files.
//!
//! Exit codes: 0 success, 1 a solve that did not converge (its partial result is still
//! reported and written), 2 bad input (the message names the file and the field).

mod cli;

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
    /// Solve a scene: summary, CSV of harmonics and time series, SVG plots.
    Solve {
        /// Scene file (.toml or .json).
        scene: PathBuf,
        /// Solver: fixed_point, newton, broyden, anderson (default: the scene's).
        #[arg(long)]
        method: Option<String>,
        /// Number of harmonics H (default: the scene's).
        #[arg(long)]
        harmonics: Option<usize>,
        /// Print exactly one JSON object on stdout instead of the summary.
        #[arg(long)]
        json: bool,
        /// Write harmonics.csv, time_series.csv and SVG plots into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Every solver and the time-domain reference on one scene.
    Compare {
        /// Scene file (.toml or .json).
        scene: PathBuf,
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
    Sweep {
        /// Scene file (.toml or .json).
        scene: PathBuf,
        /// Start speed (the scene's unit).
        #[arg(long)]
        from: f64,
        /// End speed (the scene's unit).
        #[arg(long)]
        to: f64,
        /// Print exactly one JSON object on stdout instead of the summary.
        #[arg(long)]
        json: bool,
        /// Write branch.csv and frequency_response.svg into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Largest continuation step (scaled arclength; smaller gives more points).
        #[arg(long, default_value_t = 0.5)]
        max_step: f64,
        /// Sweep this numeric scene field instead of the speed, e.g. `elements[0].alpha` or
        /// `loads[1].cos` (a warm-started sweep that does not follow folds).
        #[arg(long)]
        parameter: Option<String>,
        /// Number of values of a --parameter sweep.
        #[arg(long, default_value_t = 101)]
        points: usize,
    },
    /// Validate a scene without solving.
    Check {
        /// Scene file (.toml or .json).
        scene: PathBuf,
    },
}

fn main() -> ExitCode {
    // A bug must not greet a user with a backtrace: one line, and where to report it.
    std::panic::set_hook(Box::new(|info| {
        eprintln!("error: internal error in hbal ({info}); please report it with the scene file");
    }));
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Solve {
            scene,
            method,
            harmonics,
            json,
            out,
        } => cli::solve::solve(&scene, method.as_deref(), harmonics, json, out.as_deref()),
        Command::Compare { scene, json, out } => {
            cli::compare::compare(&scene, json, out.as_deref())
        }
        Command::Check { scene } => cli::check::check(&scene),
        Command::Sweep {
            scene,
            from,
            to,
            json,
            out,
            max_step,
            parameter,
            points,
        } => match parameter {
            Some(name) => cli::parameter_sweep::parameter_sweep(
                &scene,
                &name,
                from,
                to,
                points,
                json,
                out.as_deref(),
            ),
            None => cli::sweep::sweep(&scene, from, to, json, out.as_deref(), max_step),
        },
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(f) => {
            eprintln!("error: {:#}", f.error);
            ExitCode::from(f.code)
        }
    }
}
