//! The `hbal` command line: solve, compare and check scene files.
//!
//! Exit codes: 0 success, 1 a solve that did not converge (its partial result is still
//! reported and written), 2 bad input (the message names the file and the field).

use anyhow::Context;
use clap::{Parser, Subcommand};
use hbal::compare::relative_error;
use hbal::report::{line_plot, Axis, Series};
use hbal::scene::Scene;
use hbal::timesim::TimeSimulation;
use hbal::{HarmonicBalance, HarmonicBasis, Method, Solution};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

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

/// An error with its exit code.
struct Failure {
    code: u8,
    error: anyhow::Error,
}

impl<E: Into<anyhow::Error>> From<E> for Failure {
    fn from(e: E) -> Self {
        Failure {
            code: 2,
            error: e.into(),
        }
    }
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
        } => solve(&scene, method.as_deref(), harmonics, json, out.as_deref()),
        Command::Compare { scene, json, out } => compare(&scene, json, out.as_deref()),
        Command::Check { scene } => check(&scene),
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
            Some(name) => parameter_sweep(&scene, &name, from, to, points, json, out.as_deref()),
            None => sweep(&scene, from, to, json, out.as_deref(), max_step),
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

/// Loads the scene and applies the command-line overrides.
fn load(path: &Path, method: Option<&str>, harmonics: Option<usize>) -> Result<Scene, Failure> {
    let mut scene = Scene::load(path)?;
    if let Some(name) = method {
        scene.method = scene.method_named(name)?;
    }
    if let Some(h) = harmonics {
        let basis = HarmonicBasis::new(scene.basis.omega(), h)
            .with_context(|| format!("{}: --harmonics", scene.file))?;
        // Keep the scene's N where it can still carry H harmonics.
        scene.basis = basis.with_samples(scene.basis.samples()).unwrap_or(basis);
    }
    Ok(scene)
}

fn check(path: &Path) -> Result<u8, Failure> {
    let scene = load(path, None, None)?;
    HarmonicBalance::new(&scene.model, scene.basis).with_context(|| scene.file.clone())?;
    say!(
        "{}: ok ({} DOF(s), {} element(s), Ω = {:.6} rad/s, H = {}, N = {}, solver {})",
        scene.file,
        scene.model.n_dofs(),
        scene.model.elements().len(),
        scene.basis.omega(),
        scene.basis.harmonics(),
        scene.basis.samples(),
        scene.method.name()
    );
    Ok(0)
}

fn solve(
    path: &Path,
    method: Option<&str>,
    harmonics: Option<usize>,
    as_json: bool,
    out: Option<&Path>,
) -> Result<u8, Failure> {
    let scene = load(path, method, harmonics)?;
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--out: cannot create {}", dir.display()))?;
    }
    let hb = HarmonicBalance::new(&scene.model, scene.basis).with_context(|| scene.file.clone())?;
    let mut ws = hb.workspace();
    let start = Instant::now();
    let sol = scene.method.solve(&hb, None, &mut ws)?;
    let solve_seconds = start.elapsed().as_secs_f64();
    let dofs: Vec<_> = sol
        .dof_names()
        .iter()
        .enumerate()
        .map(|(i, name)| {
            json!({
                "name": name,
                "max_abs": sol.max_abs(i),
                "harmonics": (0..=sol.basis().harmonics()).map(|k| {
                    let (c, s) = sol.cos_sin(i, k);
                    json!({"order": k, "cos": c, "sin": s})
                }).collect::<Vec<_>>(),
            })
        })
        .collect();
    if as_json {
        let doc = json!({
            "converged": sol.is_converged(),
            "termination": sol.termination.to_string(),
            "method": scene.method.name(),
            "iterations": sol.stats.iterations,
            "residual": sol.residual(),
            "fundamental_rad_s": sol.basis().omega(),
            "harmonics": sol.basis().harmonics(),
            "samples": sol.basis().samples(),
            "solve_seconds": solve_seconds,
            "dofs": dofs,
            "history": sol.history,
        });
        say!("{doc}");
    } else {
        say!(
            "{}: {} ({}) after {} iteration{}, relative residual {:.2e}, solve {:.3} ms",
            scene.file,
            sol.termination,
            scene.method.name(),
            sol.stats.iterations,
            if sol.stats.iterations == 1 { "" } else { "s" },
            sol.residual(),
            solve_seconds * 1e3
        );
        say!(
            "  fundamental {:.6} rad/s, H = {}, N = {}, truncation estimate {:.1e}",
            sol.basis().omega(),
            sol.basis().harmonics(),
            sol.basis().samples(),
            sol.truncation_estimate()
        );
        for (i, name) in sol.dof_names().iter().enumerate() {
            say!("  max |q| {name}: {:.6e}", sol.max_abs(i));
        }
    }
    if let Some(dir) = out {
        write_outputs(dir, &sol)?;
        if !as_json {
            say!(
                "  wrote harmonics.csv, time_series.csv, time_series.svg, spectrum.svg to {}",
                dir.display()
            );
        }
    }
    Ok(if sol.is_converged() { 0 } else { 1 })
}

fn write_outputs(dir: &Path, sol: &Solution) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let h = sol.basis().harmonics();
    let mut csv = String::from("dof,order,cos,sin\n");
    for (i, name) in sol.dof_names().iter().enumerate() {
        for k in 0..=h {
            let (c, s) = sol.cos_sin(i, k);
            csv.push_str(&format!("{name},{k},{c:e},{s:e}\n"));
        }
    }
    std::fs::write(dir.join("harmonics.csv"), csv)?;
    let points = sol.basis().samples().max(256);
    let period = sol.basis().period();
    let series: Vec<Vec<f64>> = (0..sol.dof_names().len())
        .map(|i| sol.time_series(i, points))
        .collect();
    let mut csv = String::from("t,theta");
    for name in sol.dof_names() {
        csv.push_str(&format!(",{name}"));
    }
    csv.push('\n');
    for j in 0..points {
        let frac = j as f64 / points as f64;
        csv.push_str(&format!(
            "{:e},{:e}",
            frac * period,
            frac * std::f64::consts::TAU
        ));
        for s in &series {
            csv.push_str(&format!(",{:e}", s[j]));
        }
        csv.push('\n');
    }
    std::fs::write(dir.join("time_series.csv"), csv)?;
    let lines: Vec<Series> = sol
        .dof_names()
        .iter()
        .zip(&series)
        .map(|(name, s)| {
            Series::line(
                name.clone(),
                s.iter()
                    .enumerate()
                    .map(|(j, v)| (j as f64 / points as f64 * period, *v))
                    .collect(),
            )
        })
        .collect();
    line_plot(
        &dir.join("time_series.svg"),
        "Periodic solution over one period",
        &Axis::linear("t (s)"),
        &Axis::linear("q"),
        &lines,
    )
    .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    let spectra: Vec<Series> = sol
        .dof_names()
        .iter()
        .enumerate()
        .map(|(i, name)| {
            Series::markers(
                name.clone(),
                (1..=h)
                    .map(|k| (k as f64, sol.harmonic(i, k).norm()))
                    .collect(),
            )
        })
        .collect();
    if h > 0 {
        line_plot(
            &dir.join("spectrum.svg"),
            "Amplitude spectrum (static part omitted)",
            &Axis::linear("harmonic order"),
            &Axis::log("amplitude"),
            &spectra,
        )
        .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    }
    Ok(())
}

fn compare(path: &Path, as_json: bool, out: Option<&Path>) -> Result<u8, Failure> {
    let scene = load(path, None, None)?;
    let hb = HarmonicBalance::new(&scene.model, scene.basis).with_context(|| scene.file.clone())?;
    let h = scene.basis.harmonics();
    let n = scene.model.n_dofs();
    let mut solutions = Vec::new();
    for name in hbal::scene::METHODS {
        let method: Method = scene.method_named(name)?;
        let mut ws = hb.workspace();
        let start = Instant::now();
        let sol = method.solve(&hb, None, &mut ws)?;
        solutions.push((name, start.elapsed().as_secs_f64(), sol));
    }
    // The time-domain reference starts on the first converged HB orbit (from rest if none):
    // a gear pair with backlash can have coexisting orbits, and a run from rest may find
    // another one. Its error then measures the HB orbit, and grows if that orbit is unstable.
    let start_state = solutions
        .iter()
        .find(|s| s.2.is_converged())
        .map(|(_, _, sol)| {
            let q = (0..n).map(|i| sol.displacement(i, 0.0)).collect::<Vec<_>>();
            let v = (0..n).map(|i| sol.velocity(i, 0.0)).collect::<Vec<_>>();
            (q, v)
        });
    let from_orbit = start_state.is_some();
    let td = TimeSimulation {
        rtol: 1e-10,
        steady_tolerance: 1e-8,
        samples: (4 * h + 4).next_power_of_two().max(1024),
        initial: start_state,
        ..TimeSimulation::default()
    }
    .run(&scene.model, scene.basis.omega())
    .with_context(|| format!("{}: time-domain reference", scene.file))?;
    let mut rows = Vec::new();
    let mut histories = Vec::new();
    let mut any_converged = false;
    for (name, seconds, sol) in &solutions {
        let error = relative_error(sol.harmonics(), &td.harmonics, n, h);
        any_converged |= sol.is_converged();
        histories.push(Series::line(
            *name,
            sol.history
                .iter()
                .enumerate()
                .map(|(i, r)| (i as f64, *r))
                .collect(),
        ));
        rows.push(json!({
            "method": name,
            "converged": sol.is_converged(),
            "termination": sol.termination.to_string(),
            "iterations": sol.stats.iterations,
            "residual": sol.residual(),
            "solve_seconds": seconds,
            "error_vs_time_domain": error,
        }));
    }
    let td_json = json!({
        "started_on_hb_orbit": from_orbit,
        "converged": td.converged,
        "stop": format!("{:?}", td.stop),
        "periods": td.periods,
        "steps": td.steps,
        "seconds": td.wall_time.as_secs_f64(),
    });
    if as_json {
        say!(
            "{}",
            json!({"scene": scene.file, "time_domain": td_json, "methods": rows})
        );
    } else {
        say!(
            "{}: time domain (from {}) {:?} after {} periods, {} steps, {:.3} ms",
            scene.file,
            if from_orbit { "the HB orbit" } else { "rest" },
            td.stop,
            td.periods,
            td.steps,
            td.wall_time.as_secs_f64() * 1e3
        );
        say!("| method | result | iterations | wall | error vs time domain |");
        say!("|---|---|---:|---:|---:|");
        for r in &rows {
            say!(
                "| {} | {} | {} | {:.3} ms | {:.2e} |",
                r["method"].as_str().unwrap_or(""),
                r["termination"].as_str().unwrap_or(""),
                r["iterations"],
                r["solve_seconds"].as_f64().unwrap_or(f64::NAN) * 1e3,
                r["error_vs_time_domain"].as_f64().unwrap_or(f64::NAN)
            );
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        line_plot(
            &dir.join("residual_histories.svg"),
            "Residual histories",
            &Axis::linear("iteration"),
            &Axis::log("relative residual"),
            &histories,
        )
        .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
    }
    Ok(if any_converged { 0 } else { 1 })
}

fn sweep(
    path: &Path,
    from: f64,
    to: f64,
    as_json: bool,
    out: Option<&Path>,
    max_step: f64,
) -> Result<u8, Failure> {
    use hbal::continuation::{BranchStop, Continuation};
    let scene = load(path, None, None)?;
    let unit = scene.speed_unit;
    for (name, v) in [("--from", from), ("--to", to)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(
                anyhow::anyhow!("{name} must be a finite speed > 0 ({unit}), got {v}").into(),
            );
        }
    }
    if !(max_step.is_finite() && max_step > 0.0) {
        return Err(anyhow::anyhow!("--max-step must be finite and > 0, got {max_step}").into());
    }
    let per = scene.omega_per_speed;
    let basis = HarmonicBasis::new(from * per, scene.basis.harmonics())?
        .with_samples(scene.basis.samples())
        .with_context(|| scene.file.clone())?;
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    if as_json {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let start = Instant::now();
    let continuation = Continuation {
        max_step,
        ..Continuation::default()
    };
    let branch = continuation
        .run(&scene.model, basis, to * per, |f| {
            bar.set_position((f * 1000.0) as u64);
        })
        .with_context(|| scene.file.clone())?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    let speed = |omega: f64| omega / per;
    let n = scene.model.n_dofs();
    if as_json {
        let points: Vec<_> = branch
            .points
            .iter()
            .map(|p| {
                json!({
                    "speed": speed(p.omega),
                    "omega_rad_s": p.omega,
                    "stable": p.stable(),
                    "fold": p.fold,
                    "bifurcation": p.bifurcation.map(|b| format!("{b:?}")),
                    "max_abs": p.max_abs,
                    "multipliers_abs": p.floquet.as_ref().map(|f| f.multipliers.iter().map(|m| m.norm()).collect::<Vec<_>>()),
                    "harmonics": (0..n).map(|i| (0..=branch.harmonics).map(|k| {
                        let (c, s) = hbal::harmonic::cos_sin(p.harmonics[k * n + i]);
                        json!({"order": k, "cos": c, "sin": s})
                    }).collect::<Vec<_>>()).collect::<Vec<_>>(),
                })
            })
            .collect();
        say!(
            "{}",
            json!({
                "scene": scene.file,
                "unit": unit,
                "stop": branch.stop.to_string(),
                "reached": branch.stop == BranchStop::Reached,
                "points": points,
                "folds": branch.folds(),
                "seconds": seconds,
                "dofs": branch.dofs,
            })
        );
    } else {
        let unstable = branch
            .points
            .iter()
            .filter(|p| p.stable() == Some(false))
            .count();
        say!(
            "{}: {} points from {from} to {to} {unit} in {:.1} ms: {}; {} folds, {} unstable points",
            scene.file,
            branch.points.len(),
            seconds * 1e3,
            branch.stop,
            branch.folds(),
            unstable
        );
        for p in branch
            .points
            .iter()
            .filter(|p| p.fold || p.bifurcation.is_some())
        {
            let what = match (p.fold, p.bifurcation) {
                (true, Some(b)) => format!("fold, stability change ({b:?})"),
                (true, None) => "fold".to_string(),
                (false, Some(b)) => format!("stability change ({b:?})"),
                _ => unreachable!("filtered"),
            };
            say!(
                "  {what} at {:.6} {unit}, max |q| = {:.6e}",
                speed(p.omega),
                p.max_abs[0]
            );
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(
            dir.join("branch.csv"),
            hbal::report::branch_csv(&branch, unit, speed),
        )?;
        if branch.points.len() >= 2 {
            for (i, dof) in branch.dofs.iter().enumerate() {
                hbal::report::branch_plot(
                    &dir.join(format!("frequency_response_{dof}.svg")),
                    &branch,
                    i,
                    &format!("Frequency response of {dof}"),
                    &format!("speed ({unit})"),
                    speed,
                )
                .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
            }
        }
    }
    Ok(if branch.stop == BranchStop::Reached {
        0
    } else {
        1
    })
}

fn parameter_sweep(
    path: &Path,
    name: &str,
    from: f64,
    to: f64,
    points: usize,
    as_json: bool,
    out: Option<&Path>,
) -> Result<u8, Failure> {
    use hbal::continuation::{parameter_sweep, BranchStop};
    let file = path.display().to_string();
    let text =
        std::fs::read_to_string(path).with_context(|| format!("{file}: cannot read the file"))?;
    let doc = Scene::parse_value(&text, &file)?;
    if !(from.is_finite() && to.is_finite()) || points < 2 {
        return Err(anyhow::anyhow!("--from and --to must be finite and --points >= 2").into());
    }
    // Check the path and the scene once before sweeping.
    let mut probe = doc.clone();
    hbal::scene::set_parameter(&mut probe, name, from)
        .map_err(|e| anyhow::anyhow!("{file}: --parameter {e}"))?;
    Scene::from_value(probe, &file)?;
    let values: Vec<f64> = (0..points)
        .map(|i| from + (to - from) * i as f64 / (points - 1) as f64)
        .collect();
    let bar = indicatif::ProgressBar::new(points as u64);
    if as_json {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let start = Instant::now();
    let branch = parameter_sweep(
        &values,
        |p| {
            let mut d = doc.clone();
            hbal::scene::set_parameter(&mut d, name, p)
                .map_err(|e| hbal::Error::Solver { reason: e })?;
            let scene = Scene::from_value(d, &file).map_err(|e| hbal::Error::Solver {
                reason: e.to_string(),
            })?;
            Ok((scene.model, scene.basis))
        },
        None,
        |f| bar.set_position((f * points as f64) as u64),
    )
    .with_context(|| file.clone())?;
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    if as_json {
        let pts: Vec<_> = branch
            .points
            .iter()
            .map(|p| json!({"parameter": p.parameter, "stable": p.stable(), "bifurcation": p.bifurcation.map(|b| format!("{b:?}")), "max_abs": p.max_abs}))
            .collect();
        say!(
            "{}",
            json!({"scene": file, "parameter": name, "stop": branch.stop.to_string(), "reached": branch.stop == BranchStop::Reached, "seconds": seconds, "dofs": branch.dofs, "points": pts})
        );
    } else {
        say!(
            "{file}: {} values of {name} from {from} to {to} in {:.1} ms: {}",
            branch.points.len(),
            seconds * 1e3,
            branch.stop
        );
        for p in branch.points.iter().filter(|p| p.bifurcation.is_some()) {
            say!(
                "  stability change ({:?}) at {name} = {}",
                p.bifurcation.unwrap_or(hbal::stability::Bifurcation::Fold),
                p.parameter
            );
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(
            dir.join("branch.csv"),
            hbal::report::branch_csv(&branch, name, |p| p),
        )?;
        if branch.points.len() >= 2 {
            for (i, dof) in branch.dofs.iter().enumerate() {
                hbal::report::branch_plot(
                    &dir.join(format!("parameter_response_{dof}.svg")),
                    &branch,
                    i,
                    &format!("Response of {dof} against {name}"),
                    name,
                    |p| p,
                )
                .map_err(|e| anyhow::anyhow!("plot: {e}"))?;
            }
        }
    }
    Ok(if branch.stop == BranchStop::Reached {
        0
    } else {
        1
    })
}
