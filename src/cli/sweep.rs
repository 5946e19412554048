//! `hbal sweep` (without `--parameter`): follow the frequency response from `--from` to `--to`
//! through turning points by arclength continuation, with stability, and optionally write
//! branch.csv and one frequency-response SVG per DOF. The first point starts from the linear
//! solution or from a `--start` file.

use super::sweep_summary::{point_json, secondary_json, secondary_line};
use super::{load, start, Failure, SolverArgs};
use anyhow::Context;
use hbal::continuation::{Branch, BranchStop, Continuation};
use hbal::HarmonicBasis;
use num_complex::Complex64;
use serde_json::json;
use std::path::Path;
use std::time::Instant;

/// Options of a speed sweep besides the solver overrides.
pub(crate) struct SweepOptions<'a> {
    pub(crate) from: Option<f64>,
    pub(crate) to: f64,
    pub(crate) start: Option<&'a Path>,
    pub(crate) stability: bool,
    /// The orbit of the points' stability (`--stability-orbit`).
    pub(crate) orbit: hbal::stability::Orbit,
    pub(crate) max_points: Option<usize>,
    pub(crate) max_step: f64,
    /// Evenly spaced speeds of a sweep with the exact piecewise solution (no continuation).
    pub(crate) points: usize,
    pub(crate) json: bool,
    pub(crate) out: Option<&'a Path>,
    /// Switch to the branches leaving the main one at its branch points and period doublings.
    pub(crate) all_branches: bool,
    /// Estimate the error of every point against 2H.
    pub(crate) error_estimate: bool,
    /// The element or DOF the order-cut plot and the waterfall show.
    pub(crate) output: Option<&'a str>,
    /// Keep the JSON document here instead of printing anything (for `hbal report`).
    pub(crate) capture: super::Capture<'a>,
    /// `--dofs`: the DOFs whose harmonics and plots are written ([`super::dof_selection`]).
    pub(crate) dofs: Option<&'a str>,
}

/// The branch from `basis.omega()` to `to`, from the orbit `initial` if given.
fn run(
    continuation: &Continuation,
    model: &hbal::Model,
    basis: HarmonicBasis,
    to: f64,
    initial: Option<&[Complex64]>,
    points: usize,
    progress: impl FnMut(f64),
) -> hbal::Result<Branch> {
    if matches!(continuation.method, hbal::solve::Method::PiecewiseExact(_)) {
        // A linear scene has no turning points: the exact solution at `points` evenly spaced
        // speeds, each with its own estimate, extremes and multipliers.
        let from = basis.omega();
        let values: Vec<f64> = (0..points)
            .map(|i| from + (to - from) * i as f64 / (points - 1) as f64)
            .collect();
        return hbal::continuation::sweep_values(
            &values,
            |w| Ok((model, basis.with_omega(w)?)),
            continuation,
            progress,
        );
    }
    continuation.run_from(model, basis, to, initial, progress)
}

/// The branch with automatic harmonics held along it ([`Continuation::run_auto`]) as one
/// branch on the last segment's basis (returned): the segments' points in order, each padded
/// with zeros to the last H (exact: a point has no content above its own H), the last
/// segment's stop, and a note of where H rose.
fn run_auto(
    continuation: &Continuation,
    scene: &hbal::scene::Scene,
    basis: HarmonicBasis,
    to: f64,
    initial: &[Complex64],
    auto: hbal::solve::AutoHarmonics,
    bar: &super::progress::Progress,
) -> Result<(Branch, HarmonicBasis), Failure> {
    let mut segments = continuation
        .run_auto(&scene.model, basis, to, Some(initial), auto, |f| bar.set(f))
        .map_err(|e| super::sweep_failure(e, &scene.file))?;
    let mut branch = segments.remove(0);
    let mut steps = vec![format!("H = {}", branch.harmonics)];
    for s in segments {
        if let hbal::continuation::BranchStop::HarmonicsChanged { omega, harmonics } = branch.stop {
            steps.push(format!("H = {harmonics} from {omega:.6} rad/s"));
        }
        branch.points.extend(s.points);
        branch.stop = s.stop;
    }
    if steps.len() > 1 {
        eprintln!("note: harmonics along the branch: {}", steps.join(", "));
    }
    let n = branch.dofs.len();
    let top = branch
        .points
        .iter()
        .map(|p| p.harmonics.len() / n.max(1))
        .max()
        .unwrap_or(1)
        .saturating_sub(1);
    for p in &mut branch.points {
        p.harmonics.resize((top + 1) * n, Complex64::default());
    }
    let ratio = top.max(1) as f64 / basis.harmonics().max(1) as f64;
    let last = HarmonicBasis::new(basis.omega(), top)?
        .with_tail_correction_of(&basis)
        .with_subharmonic(basis.subharmonic())?
        .with_samples(((basis.samples() as f64 * ratio).ceil() as usize).max(4 * top + 1))?;
    branch.harmonics = top;
    Ok((branch, last))
}

pub(crate) fn sweep(path: &Path, args: &SolverArgs, opts: SweepOptions) -> Result<u8, Failure> {
    let as_json = opts.json || opts.capture.is_some();
    let (to, out, max_step) = (opts.to, opts.out, opts.max_step);
    let scene = load(path, args)?;
    let shown = super::order_cuts::choose(&scene, opts.output)?;
    let reported = super::dof_selection::reported_dofs(&scene.model, opts.dofs)?;
    if let Some(dir) = out {
        for dof in scene.model.dof_names() {
            super::file_name_part(dof, "DOF")?;
        }
        super::prepare_out(dir)?;
    }
    let unit = scene.speed_unit;
    let per = scene.omega_per_speed;
    let start = opts.start.map(|p| start::read(p, &scene)).transpose()?;
    if matches!(scene.method, hbal::solve::Method::PiecewiseExact(_)) {
        if let Some(file) = opts.start {
            eprintln!(
                "note: --start {} is not used: the exact piecewise solution needs no start",
                file.display()
            );
        }
        if opts.orbit == hbal::stability::Orbit::Harmonic {
            eprintln!(
                "note: --stability-orbit harmonic is not used: the exact piecewise solution's multipliers are its exact orbit's"
            );
        }
    }
    // Default start speed: the start file's, else the scene's.
    let from = opts.from.unwrap_or_else(|| {
        start
            .as_ref()
            .and_then(|s| s.omega)
            .unwrap_or(scene.basis.omega())
            / per
    });
    for (name, v) in [("--from", from), ("--to", to)] {
        hbal::analysis::check_speed(&scene, name, v, false).map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    hbal::analysis::check_sweep_start(&scene, from * per, args.formulation)
        .map_err(|e| super::failure(e, &scene.file))?;
    if !(max_step.is_finite() && max_step > 0.0) {
        return Err(anyhow::anyhow!("--max-step must be finite and > 0, got {max_step}").into());
    }
    if let Some(e) = scene.model.memory_element().filter(|_| opts.all_branches) {
        return Err(anyhow::anyhow!(
            "--all-branches: branch switching is not available for laws with memory (element `{}`)",
            e.name()
        )
        .into());
    }
    if opts.all_branches && !opts.stability {
        return Err(anyhow::anyhow!(
            "--all-branches needs the stability of the points (drop --no-stability): branch points and period doublings are found from the Floquet multipliers"
        )
        .into());
    }
    if opts.max_points == Some(0) {
        return Err(anyhow::anyhow!("--max-points must be at least 1").into());
    }
    if let (Some(file), Some(w)) = (opts.start, start.as_ref().and_then(|s| s.omega)) {
        if (w - from * per).abs() > 1e-9 * w {
            eprintln!(
                "note: --start {} was computed at {} {unit}; the sweep starts at {from} {unit}",
                file.display(),
                w / per
            );
        }
    }
    let mut basis = HarmonicBasis::new(from * per, scene.basis.harmonics())?
        .with_tail_correction_of(&scene.basis)
        .with_samples(scene.basis.samples())
        .with_context(|| scene.file.clone())?;
    // Automatic harmonics: H chosen at the first speed, then raised along the branch where a
    // point exceeds the tolerance (kept with --all-branches, whose switching needs one H).
    let mut auto_start = None;
    if let Some(auto) = scene.auto {
        let a = hbal::solve::solve_auto(&scene.model, basis, &scene.method, auto)
            .map_err(|e| super::failure(e, &scene.file))?;
        basis = *a.solution.basis();
        let raised = !opts.all_branches && a.exact.is_none() && !a.capped;
        eprintln!(
            "note: harmonics: auto, tolerance {:.0e}{}: H = {} (error estimate {:.1e} at {from} {unit}{}), {}",
            auto.tolerance,
            auto.control.pick("", " on the harmonics 0..H"),
            basis.harmonics(),
            auto.control.of(&a.estimate),
            if a.capped { ", above the tolerance at the cap" } else { "" },
            if raised { "raised along the branch where a point exceeds the tolerance" } else { "kept along the branch" }
        );
        if raised {
            auto_start = Some((auto, a.solution.harmonics().to_vec()));
        }
    }
    let bar = super::progress::Progress::new("sweep", as_json);
    let defaults = Continuation::default();
    let continuation = Continuation {
        max_step,
        method: scene.method,
        tolerance: args.tolerance.unwrap_or(defaults.tolerance),
        max_points: opts.max_points.unwrap_or(defaults.max_points),
        stability: defaults.stability.filter(|_| opts.stability).map(|f| {
            hbal::stability::FloquetOptions {
                orbit: opts.orbit,
                ..f
            }
        }),
        error_estimate: opts.error_estimate,
        formulation: args.formulation,
        ..defaults
    };
    let started = Instant::now();
    let branch = match &auto_start {
        Some((auto, q)) => {
            let (branch, last) = run_auto(&continuation, &scene, basis, to * per, q, *auto, &bar)?;
            basis = last;
            branch
        }
        None => run(
            &continuation,
            &scene.model,
            basis,
            to * per,
            start.as_ref().map(|s| s.harmonics.as_slice()),
            opts.points,
            |f| bar.set(f),
        )
        .map_err(|e| super::sweep_failure(e, &scene.file))?,
    };
    let (lo, hi) = (from.min(to) * per, from.max(to) * per);
    let secondary = if opts.all_branches {
        bar.message("switching branches");
        continuation
            .switch_branches(&scene.model, basis, &branch, lo, hi)
            .map_err(|e| super::sweep_failure(e, &scene.file))?
    } else {
        Vec::new()
    };
    bar.finish();
    let seconds = started.elapsed().as_secs_f64();
    let speed = |omega: f64| omega / per;
    // The library never gives a non-finite multiplier; should it, that is a failure, not `null`.
    let broken = branch.points.iter().find_map(|p| {
        p.floquet
            .as_ref()
            .and_then(|f| super::check_finite(f).err())
            .map(|e| (p.omega, e))
    });
    let fold_speeds: Vec<f64> = branch
        .points
        .iter()
        .filter(|p| p.fold)
        .map(|p| speed(p.fold_omega.unwrap_or(p.omega)))
        .collect();
    // Where contacts open along the branch (backlash, gap contacts).
    let outputs = super::order_cuts::point_outputs(&scene, &branch, &basis)?;
    let contact_loss = super::order_cuts::contact_loss(&scene, &branch, &outputs, speed);
    if as_json {
        let points: Vec<_> = branch
            .points
            .iter()
            .map(|p| point_json(p, &branch, &reported, scene.fundamental_order, speed))
            .collect();
        super::emit(
            json!({
                "scene": scene.file,
                "unit": unit,
                "from": from,
                "to": to,
                "first_point": branch.start,
                "stop": branch.stop.to_string(),
                "reached": branch.stop == BranchStop::Reached,
                "points": points,
                "folds": branch.folds(),
                "fold_speeds": fold_speeds,
                "spurious_turns": branch.spurious_turns(),
                "seconds": seconds,
                "dofs": branch.dofs,
                "harmonics_dofs": reported.iter().map(|&i| &branch.dofs[i]).collect::<Vec<_>>(),
                "branches": secondary.iter().map(|b| secondary_json(b, &reported, scene.fundamental_order, speed)).collect::<Vec<_>>(),
                "contact_loss": contact_loss,
            }),
            opts.capture,
        );
    } else {
        let unstable = branch
            .points
            .iter()
            .filter(|p| p.stable() == Some(false))
            .count();
        let spurious = branch.spurious_turns();
        say!(
            "{}: {} points from {} to {} {unit} in {:.1} ms: {}; {} fold{}, {} unstable point{}{}",
            scene.file,
            branch.points.len(),
            super::speed_text(from),
            super::speed_text(to),
            seconds * 1e3,
            branch.stop,
            branch.folds(),
            if branch.folds() == 1 { "" } else { "s" },
            unstable,
            if unstable == 1 { "" } else { "s" },
            if spurious > 0 {
                format!(
                    ", {spurious} spurious turn{} (corners or zig-zags the multipliers do not confirm)",
                    if spurious == 1 { "" } else { "s" }
                )
            } else {
                String::new()
            }
        );
        let orbits = super::sweep_summary::orbit_lines(&branch, unit, speed);
        for line in &orbits {
            say!("  {line}");
        }
        if orbits.is_empty() {
            if let Some(hint) = super::sweep_summary::orbit_hint(&branch) {
                say!("  {hint}");
            }
        }
        let unavailable = !hbal::stability::memory_stability_available(&scene.model);
        if let Some(e) = scene
            .model
            .memory_element()
            .filter(|_| opts.stability && unavailable)
        {
            say!(
                "  stability unknown: not available for laws with memory (element `{}`) in a free-free model or above {} DOFs",
                e.name(),
                hbal::stability::MAX_MEMORY_DOFS
            );
        }
        if let Some(note) = out.and(super::dof_selection::note(&scene.model, &reported)) {
            say!("  {note}");
        }
        for c in &contact_loss {
            say!(
                "  contact `{}` opens from {} to {} {unit} (up to {:.1} % of the period)",
                c.element,
                super::speed_text(c.from),
                super::speed_text(c.to),
                100.0 * c.max_open
            );
        }
        let worst = branch
            .points
            .iter()
            .filter_map(|p| p.error_estimate.map(|e| (e, p.omega)))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((e, w)) = worst {
            let kept = branch
                .points
                .iter()
                .filter_map(|p| p.error_estimate_harmonics)
                .fold(f64::NAN, f64::max);
            say!(
                "  largest error estimate {e:.1e} (at {:.6} {unit}){} ({})",
                speed(w),
                if kept.is_nan() {
                    String::new()
                } else {
                    format!(", of harmonics 0..{} {kept:.1e}", branch.harmonics)
                },
                if matches!(scene.method, hbal::solve::Method::PiecewiseExact(_)) {
                    "what the exact solution lacks above H, and rounding".to_string()
                } else if scene.model.is_linear_time_invariant() {
                    "a linear time-invariant model is exact in H: rounding, by iterative refinement"
                        .to_string()
                } else {
                    format!(
                        "against 2H = {}, more where a jumping stiffness rings above it",
                        2 * branch.harmonics
                    )
                }
            );
        }
        let worst_quantity = branch
            .points
            .iter()
            .filter_map(|p| p.worst_quantity.map(|q| (q, p.omega)))
            .max_by(|a, b| a.0.error.total_cmp(&b.0.error));
        if let Some((q, w)) = worst_quantity {
            say!(
                "  worst quantity {} {:.1e} of its range {:.3e} (at {:.6} {unit}; dynamic part, with what H lacks)",
                q.quantity.name(&scene.model),
                q.error,
                q.range,
                speed(w)
            );
        }
        let quadrature = branch
            .points
            .iter()
            .filter_map(|p| p.quadrature.map(|q| (q, p.omega)))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((q, w)) = quadrature {
            say!(
                "  contact quadrature up to {q:.1e} of the load (at {:.6} {unit}; a law with kinks that is not affine between them takes the corrected trapezoid rule, measured against 8 times the samples)",
                speed(w)
            );
        }
        let failed_start = matches!(branch.stop, BranchStop::StartFailed { .. });
        if !branch.start.is_empty() && branch.start != scene.method.name() && !failed_start {
            say!("  first point: {}", branch.start);
        }
        for p in branch
            .points
            .iter()
            .filter(|p| p.fold || p.bifurcation.is_some())
        {
            let at = match (p.fold, p.fold_omega, p.bifurcation_omega) {
                (true, Some(w), _) => format!("{:.7} {unit} (interpolated)", speed(w)),
                (false, _, Some(w)) => format!("{:.7} {unit} (located)", speed(w)),
                _ => format!("{:.6} {unit}", speed(p.omega)),
            };
            let what = match (p.fold, p.bifurcation) {
                (true, Some(b)) => format!("fold at {at}, stability change ({b:?})"),
                (true, None) => format!("fold at {at}"),
                (false, Some(b)) => format!("stability change ({b:?}) at {at}"),
                _ => unreachable!("filtered"),
            };
            say!("  {what}, max |q| = {:.6e}", p.max_abs[0]);
        }
        for (p, e) in branch
            .points
            .iter()
            .filter(|p| p.spurious_turn)
            .filter_map(|p| p.turn_evidence.map(|e| (p, e)))
        {
            let text = |w: f64| format!("{} {unit}", super::speed_text(speed(w)));
            say!(
                "  turn at {} not a fold: {}",
                text(p.fold_omega.unwrap_or(p.omega)),
                e.describe(&text)
            );
        }
        for b in &secondary {
            say!("  {}", secondary_line(b, unit, speed));
        }
    }
    if let Some(dir) = out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(
            dir.join("branch.csv"),
            hbal::report::branch_csv_of_dofs(
                &branch,
                scene.fundamental_order,
                &reported,
                unit,
                speed,
            ),
        )?;
        super::order_cuts::write(
            dir,
            &scene,
            &branch,
            &basis,
            &outputs,
            super::order_cuts::Shows {
                dofs: &reported,
                plotted: shown,
            },
            speed,
        )?;
        for (i, b) in secondary.iter().enumerate() {
            std::fs::write(
                dir.join(format!("branch_{}.csv", i + 1)),
                hbal::report::branch_csv_of_dofs(
                    b,
                    scene.fundamental_order,
                    &reported,
                    unit,
                    speed,
                ),
            )?;
        }
        if branch.points.len() >= 2 {
            let all: Vec<&Branch> = std::iter::once(&branch).chain(&secondary).collect();
            for &i in &reported {
                let dof = &branch.dofs[i];
                hbal::report::branches_plot(
                    &dir.join(format!("frequency_response_{dof}.svg")),
                    &all,
                    i,
                    &format!(
                        "Frequency response of {dof}: {}{}",
                        scene.file,
                        if branch.stop == BranchStop::Reached {
                            String::new()
                        } else {
                            format!(" - STOPPED: {}", branch.stop)
                        }
                    ),
                    &format!("speed ({unit})"),
                    speed,
                )
                .unwrap_or_else(super::plot_warning);
            }
        }
    }
    if branch.stop != BranchStop::Reached {
        eprintln!("error: {}: the branch stopped: {}", scene.file, branch.stop);
    }
    if let Some((omega, e)) = broken {
        eprintln!(
            "error: {}: stability at {} {unit}: {e}",
            scene.file,
            speed(omega)
        );
        return Ok(1);
    }
    // Automatic harmonics chose H at the first speed: say so if the branch needs more.
    if let Some(auto) = scene.auto {
        let worst = branch
            .points
            .iter()
            .filter_map(|p| {
                let e = auto
                    .control
                    .pick(p.error_estimate, p.error_estimate_harmonics);
                e.map(|e| (e, p.omega))
            })
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((e, w)) = worst.filter(|(e, _)| *e > auto.tolerance) {
            eprintln!(
                "warning: {}: error estimate{} up to {e:.1e} (at {} {unit}), above the tolerance {:.0e} of the H = {} chosen at the first speed: start the sweep there or raise harmonics.count",
                scene.file,
                auto.control.pick("", " of the harmonics 0..H"),
                speed(w),
                auto.tolerance,
                branch.harmonics
            );
        }
    }
    let failed: Vec<&Branch> = secondary
        .iter()
        .filter(|b| !b.stop.is_normal_end())
        .collect();
    for b in &failed {
        eprintln!(
            "error: {}: a switched branch stopped: {}",
            scene.file,
            secondary_line(b, unit, speed)
        );
    }
    Ok(if branch.stop == BranchStop::Reached && failed.is_empty() {
        0
    } else {
        1
    })
}
