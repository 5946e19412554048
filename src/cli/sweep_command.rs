//! The options of `hbal sweep` and their dispatch: a speed sweep ([`super::sweep`]) or, with
//! `--parameter`, a sweep of a scene field ([`super::parameter_sweep`]).

use super::{Failure, SolverArgs};
use std::path::PathBuf;

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
pub(crate) fn sweep_points(min: u64) -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::new().range(min..=MAX_SWEEP_POINTS)
}

/// The flags of `hbal sweep`.
#[derive(clap::Args)]
pub(crate) struct SweepCommand {
    /// Scene file (.toml or .json).
    scene: PathBuf,
    /// Start speed (the scene's unit; default: the --start file's speed, else the scene's).
    #[arg(long, allow_negative_numbers = true)]
    from: Option<f64>,
    /// End speed (the scene's unit).
    #[arg(long, allow_negative_numbers = true)]
    to: f64,
    #[command(flatten)]
    solver: SolverArgs,
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
}

impl SweepCommand {
    /// Runs the sweep the flags ask for.
    pub(crate) fn run(self) -> Result<u8, Failure> {
        let exact = hbal::stability::Orbit::Exact;
        let refuse = |why: &str| Err(Failure::from(anyhow::anyhow!("{why}")));
        if self.no_stability && self.stability_orbit != exact {
            return refuse("--stability-orbit chooses the orbit of the points' stability; drop --no-stability or --stability-orbit");
        }
        let Some(name) = &self.parameter else {
            return self.speed_sweep();
        };
        if self.stability_orbit != exact {
            return refuse("--stability-orbit applies to speed sweeps, not to --parameter sweeps");
        }
        if self.output.is_some() {
            return refuse("--output chooses the order-cut plot of a speed sweep; it does not apply to --parameter sweeps");
        }
        if self.all_branches {
            return refuse("--all-branches follows branches in the speed; it does not apply to --parameter sweeps");
        }
        super::parameter_sweep::parameter_sweep(
            &self.scene,
            name,
            super::parameter_sweep::ParameterSweep {
                from: self.from,
                to: self.to,
                points: self.points,
                solver: &self.solver,
                start: self.start.as_deref(),
                stability: !self.no_stability,
                json: self.json,
                out: self.out.as_deref(),
                dofs: self.dofs.as_deref(),
            },
        )
    }

    /// A sweep in the speed.
    fn speed_sweep(&self) -> Result<u8, Failure> {
        super::sweep::sweep(
            &self.scene,
            &self.solver,
            super::sweep::SweepOptions {
                from: self.from,
                to: self.to,
                start: self.start.as_deref(),
                stability: !self.no_stability,
                orbit: self.stability_orbit,
                max_points: self.max_points,
                max_step: self.max_step,
                points: self.points,
                json: self.json,
                out: self.out.as_deref(),
                all_branches: self.all_branches,
                error_estimate: !self.no_error_estimate,
                output: self.output.as_deref(),
                dofs: self.dofs.as_deref(),
            },
        )
    }
}
