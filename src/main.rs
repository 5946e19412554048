//! The `hbal` command line: solve, compare and check scene files.
//!
//! Exit codes: 0 success, 1 a numerical failure: a solve that did not converge, a branch that
//! stopped before `--to`, a failed stability computation (the partial result is still reported
//! and written), 2 bad input (the message names the file and the field).

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
    Sweep {
        /// Scene file (.toml or .json).
        scene: PathBuf,
        /// Start speed (the scene's unit; default: the --start file's speed, else the scene's).
        #[arg(long, allow_negative_numbers = true)]
        from: Option<f64>,
        /// End speed (the scene's unit).
        #[arg(long, allow_negative_numbers = true)]
        to: f64,
        #[command(flatten)]
        solver: cli::SolverArgs,
        /// Start the branch from a previous `hbal solve --json` result.
        #[arg(long, value_name = "FILE")]
        start: Option<PathBuf>,
        /// Skip the Floquet stability of the points.
        #[arg(long)]
        no_stability: bool,
        /// The orbit whose Floquet multipliers a point gets: `exact` (shooting onto the exact
        /// periodic orbit) or `harmonic` (the HB orbit's own pieces, no integration: a
        /// fraction of the cost where every law is piecewise affine; checked against the
        /// exact orbit along the way, and the exact orbit's where a multiplier is too close
        /// to the unit circle to call).
        #[arg(long, default_value = "exact", value_parser = parse_orbit)]
        stability_orbit: hbal::stability::Orbit,
        /// Stop after this many points (exit code 1 if --to is not reached; default 2000, at
        /// most 100000).
        #[arg(long, value_parser = sweep_points(1))]
        max_points: Option<usize>,
        /// Print exactly one JSON object on stdout instead of the summary.
        #[arg(long)]
        json: bool,
        /// Write branch.csv, frequency_response_<dof>.svg, order_cuts.csv, order_cuts.svg and
        /// waterfall.svg into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
        /// The element or DOF whose order cuts and waterfall are plotted (default: the first
        /// gear stage's transmission error, else the DOF that moves most).
        #[arg(long, value_name = "NAME")]
        output: Option<String>,
        /// Skip the error estimate of every point (a solve with 2H harmonics per point).
        #[arg(long)]
        no_error_estimate: bool,
        /// Also follow every branch that leaves the swept one: at a branch point (symmetry
        /// breaking) both new branches, at a period doubling the period-2 orbits (harmonics
        /// of half the speed). Needs the stability; writes branch_1.csv, ... with --out.
        #[arg(long)]
        all_branches: bool,
        /// Largest continuation step (scaled arclength; smaller gives more points).
        #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
        max_step: f64,
        /// The DOFs whose harmonics (branch.csv; a speed sweep's JSON and order_cuts.csv) and
        /// response plots are written: comma-separated names, or `all` (default: every DOF up to 64, else the DOFs
        /// that elements and loads act on; max |q| of every DOF is always written).
        #[arg(long, value_name = "NAMES")]
        dofs: Option<String>,
        /// Sweep this numeric scene field instead of the speed, e.g. `elements[0].alpha` or
        /// `loads[1].cos` (a warm-started sweep that does not follow folds).
        #[arg(long)]
        parameter: Option<String>,
        /// Number of values of a --parameter sweep, or of speeds of a sweep with method
        /// piecewise_exact (evenly spaced; a linear scene needs no continuation) (2 to 100000).
        #[arg(long, default_value_t = 101, value_parser = sweep_points(2))]
        points: usize,
    },
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
        #[command(flatten)]
        solver: cli::SolverArgs,
    },
    /// Validate a scene without solving.
    Check {
        /// Scene file (.toml or .json).
        scene: PathBuf,
    },
}

/// Largest number of points of a sweep (`--max-points`, `--points`): bounds its time.
const MAX_SWEEP_POINTS: u64 = 100_000;

/// `exact` or `harmonic`.
fn parse_orbit(s: &str) -> Result<hbal::stability::Orbit, String> {
    match s {
        "exact" => Ok(hbal::stability::Orbit::Exact),
        "harmonic" => Ok(hbal::stability::Orbit::Harmonic),
        _ => Err(format!("`{s}`: expected `exact` or `harmonic`")),
    }
}

/// A point count from `min` to [`MAX_SWEEP_POINTS`].
fn sweep_points(min: u64) -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::new().range(min..=MAX_SWEEP_POINTS)
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
                capture: None,
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
                capture: None,
            },
        ),
        Command::Sweep {
            scene,
            from,
            to,
            solver,
            start,
            no_stability,
            stability_orbit,
            max_points,
            json,
            out,
            max_step,
            all_branches,
            no_error_estimate,
            parameter,
            points,
            output,
            dofs,
        } => match parameter {
            _ if no_stability && stability_orbit != hbal::stability::Orbit::Exact => {
                Err(cli::Failure::from(anyhow::anyhow!(
                    "--stability-orbit chooses the orbit of the points' stability; drop --no-stability or --stability-orbit"
                )))
            }
            Some(_) if stability_orbit != hbal::stability::Orbit::Exact => {
                Err(cli::Failure::from(anyhow::anyhow!(
                    "--stability-orbit applies to speed sweeps, not to --parameter sweeps"
                )))
            }
            Some(_) if output.is_some() => Err(cli::Failure::from(anyhow::anyhow!(
                "--output chooses the order-cut plot of a speed sweep; it does not apply to --parameter sweeps"
            ))),
            Some(_) if all_branches => Err(cli::Failure::from(anyhow::anyhow!(
                "--all-branches follows branches in the speed; it does not apply to --parameter sweeps"
            ))),
            Some(name) => cli::parameter_sweep::parameter_sweep(
                &scene,
                &name,
                cli::parameter_sweep::ParameterSweep {
                    from,
                    to,
                    points,
                    solver: &solver,
                    start: start.as_deref(),
                    stability: !no_stability,
                    json,
                    out: out.as_deref(),
                    dofs: dofs.as_deref(),
                },
            ),
            None => cli::sweep::sweep(
                &scene,
                &solver,
                cli::sweep::SweepOptions {
                    from,
                    to,
                    start: start.as_deref(),
                    stability: !no_stability,
                    orbit: stability_orbit,
                    max_points,
                    max_step,
                    points,
                    json,
                    out: out.as_deref(),
                    all_branches,
                    error_estimate: !no_error_estimate,
                    output: output.as_deref(),
                    capture: None,
                    dofs: dofs.as_deref(),
                },
            ),
        },
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(f) => {
            eprintln!("error: {}", cli::printable(&format!("{:#}", f.error)));
            ExitCode::from(f.code)
        }
    }
}
