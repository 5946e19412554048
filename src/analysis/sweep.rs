//! A speed sweep of a scene with everything `hbal sweep` reports ([`sweep()`]).
//!
//! The path taken: the options checked against the scene before any work (speeds, the first
//! point's harmonic balance, branch switching's needs); automatic harmonics choose H at the
//! first speed and, unless branches are switched, raise it along the branch where a point
//! exceeds the tolerance ([`Continuation::run_auto`]); the exact piecewise method solves
//! evenly spaced speeds (a linear scene has no turning points); otherwise pseudo-arclength
//! continuation from the linear solution or the start harmonics. Then the branches leaving
//! the main one where asked, every point's element outputs and where contacts open.

use super::branch_outputs::{contact_loss, point_outputs, ContactLoss};
use super::observer::Observer;
use super::output_choice::{reported_dofs, shown_output, Shown};
use super::sweep_outcome::SweepNote;
use super::sweep_settings::SweepSettings;
use crate::continuation::{Branch, BranchStop, Continuation};
use crate::report::ElementOutput;
use crate::scene::Scene;
use crate::solve::{AutoHarmonics, Method};
use crate::stability::{FloquetOptions, Orbit};
use crate::{Error, HarmonicBasis, Result};
use num_complex::Complex64;
use std::time::Instant;

/// Everything one speed sweep of a scene gives ([`sweep()`]); its serde form is
/// `hbal sweep --json`.
#[derive(Debug, Clone)]
pub struct SweepAnalysis {
    /// The scene's file (or name).
    pub file: String,
    /// The scene's speed unit.
    pub unit: String,
    /// rad/s of the fundamental per unit of speed.
    pub omega_per_speed: f64,
    /// The fundamental's order of the reference speed.
    pub fundamental_order: f64,
    /// The first and last speed (the scene's unit).
    pub from: f64,
    /// The last speed.
    pub to: f64,
    /// The main branch (with automatic harmonics its segments padded to the last H).
    pub branch: Branch,
    /// The basis of the branch's last H (the points' harmonics are on it).
    pub basis: HarmonicBasis,
    /// The branches leaving the main one.
    pub secondary: Vec<Branch>,
    /// Every element's output at every point of the main branch.
    pub outputs: Vec<Vec<ElementOutput>>,
    /// Where contacts open along the main branch.
    pub contact_loss: Vec<ContactLoss>,
    /// The DOFs reported in full.
    pub reported: Vec<usize>,
    /// The output the order-cut plot shows.
    pub shown: Shown,
    /// The scene's automatic harmonics, where on.
    pub auto: Option<AutoHarmonics>,
    /// Notes for the user.
    pub notes: Vec<SweepNote>,
    /// Why the points have no stability though it was asked for (laws with memory in a
    /// free-free or large model).
    pub stability_unavailable: Option<String>,
    /// Wall time of the continuation and branch switching, s.
    pub seconds: f64,
}

/// The checked options of a sweep.
struct Plan {
    from: f64,
    reported: Vec<usize>,
    shown: Shown,
    notes: Vec<SweepNote>,
}

/// Sweeps `scene` with `settings` (module documentation), reporting progress to `observer`.
///
/// # Errors
/// Bad input, found before any work ([`Error::InvalidOptions`], what the first point's
/// harmonic balance refuses); a failure along the branch is [`Error::AfterCheck`]. A branch
/// that stops early is a result, marked by its [`BranchStop`].
pub fn sweep(
    scene: &Scene,
    settings: &SweepSettings,
    observer: &mut dyn Observer,
) -> Result<SweepAnalysis> {
    let mut plan = plan(scene, settings)?;
    let per = scene.omega_per_speed;
    let mut basis = HarmonicBasis::new(plan.from * per, scene.basis.harmonics())?
        .with_tail_correction_of(&scene.basis)
        .with_samples(scene.basis.samples())?;
    let mut auto_start = None;
    if let Some(auto) = scene.auto {
        let a = crate::solve::solve_auto(&scene.model, basis, &scene.method, auto)?;
        basis = *a.solution.basis();
        let raised = !settings.all_branches && a.exact.is_none() && !a.capped;
        plan.notes.push(SweepNote::AutoHarmonics {
            settings: auto,
            harmonics: basis.harmonics(),
            estimate: auto.control.of(&a.estimate),
            capped: a.capped,
            from: plan.from,
            raised,
        });
        if raised {
            auto_start = Some((auto, a.solution.harmonics().to_vec()));
        }
    }
    let continuation = continuation_of(scene, settings);
    let started = Instant::now();
    let to = settings.to * per;
    let mut progress = |f: f64| observer.progress(f);
    let mut branch = match &auto_start {
        Some((auto, q)) => {
            let segments = continuation
                .run_auto(&scene.model, basis, to, Some(q), *auto, &mut progress)
                .map_err(Error::after_check)?;
            let (branch, last, note) = joined(segments, basis)?;
            plan.notes.extend(note);
            basis = last;
            branch
        }
        None => {
            let initial = settings.start.as_ref().map(|s| s.harmonics.as_slice());
            main_branch(
                &continuation,
                scene,
                basis,
                to,
                initial,
                settings.points,
                progress,
            )
            .map_err(Error::after_check)?
        }
    };
    let secondary = if settings.all_branches {
        observer.stage("switching branches");
        let (lo, hi) = (
            plan.from.min(settings.to) * per,
            plan.from.max(settings.to) * per,
        );
        let switched = continuation
            .switch_branches(&scene.model, basis, &branch, lo, hi)
            .map_err(Error::after_check)?;
        // Cancelled while switching: the bifurcations after it were not followed.
        if settings.cancel.is_cancelled() {
            let parameter = branch.points.last().map_or(0.0, |p| p.omega);
            branch.stop = BranchStop::Cancelled { parameter };
        }
        switched
    } else {
        Vec::new()
    };
    let seconds = started.elapsed().as_secs_f64();
    let outputs = point_outputs(&scene.model, &branch, &basis).map_err(Error::after_check)?;
    let contact_loss = contact_loss(&scene.model, &branch, &outputs, |w| w / per);
    Ok(SweepAnalysis {
        file: scene.file.clone(),
        unit: scene.speed_unit.to_string(),
        omega_per_speed: per,
        fundamental_order: scene.fundamental_order,
        from: plan.from,
        to: settings.to,
        branch,
        basis,
        secondary,
        outputs,
        contact_loss,
        reported: plan.reported,
        shown: plan.shown,
        auto: scene.auto,
        notes: plan.notes,
        stability_unavailable: stability_unavailable(scene, settings),
        seconds,
    })
}

/// Checks `settings` against `scene` as [`sweep()`] does before any work (a front end that
/// prepares output files calls it first).
///
/// # Errors
/// What [`sweep()`] refuses as bad input.
pub fn check_sweep(scene: &Scene, settings: &SweepSettings) -> Result<()> {
    plan(scene, settings).map(|_| ())
}

/// The options of `settings` checked against `scene`, the first speed and the notes on them.
fn plan(scene: &Scene, settings: &SweepSettings) -> Result<Plan> {
    scene.require_operating_point("sweep")?;
    let shown = shown_output(scene, settings.output.as_deref())?;
    let reported = reported_dofs(&scene.model, settings.dofs.as_deref())?;
    let per = scene.omega_per_speed;
    let start_omega = settings.start.as_ref().and_then(|s| s.omega);
    let from = settings
        .from
        .unwrap_or_else(|| start_omega.unwrap_or(scene.basis.omega()) / per);
    super::check_speed(scene, "--from", from, false)?;
    super::check_speed(scene, "--to", settings.to, false)?;
    scene
        .model
        .check_load_speeds(from * per, settings.to * per)?;
    if let Some(s) = &settings.start {
        if scene.auto.is_some() {
            return Err(Error::InvalidOptions {
                option: "--start".into(),
                reason: "needs a fixed H: give --harmonics N (automatic harmonics start the sweep from their own solve at the first speed)".into(),
            });
        }
        super::solve::check_start(scene, &s.harmonics, &s.label)?;
    }
    super::check_sweep_start(scene, from * per, settings.formulation)?;
    let bad = |option: &str, reason: String| Error::InvalidOptions {
        option: option.into(),
        reason,
    };
    if !(settings.max_step.is_finite() && settings.max_step > 0.0) {
        let got = crate::report::significant(settings.max_step, 6);
        return Err(bad(
            "--max-step",
            format!("must be finite and > 0, got {got}"),
        ));
    }
    if let Some(e) = scene
        .model
        .memory_element()
        .filter(|_| settings.all_branches)
    {
        return Err(bad("--all-branches", format!(
            "is not available for laws with memory (element `{}`): branch switching needs a smooth branch",
            e.name()
        )));
    }
    if settings.all_branches && !settings.stability {
        return Err(bad("--all-branches", "needs the stability of the points (drop --no-stability): branch points and period doublings are found from the Floquet multipliers".into()));
    }
    if settings.max_points == Some(0) {
        return Err(bad("--max-points", "must be at least 1".into()));
    }
    if matches!(scene.method, Method::PiecewiseExact(_)) && settings.points < 2 {
        return Err(bad("--points", "must be at least 2".into()));
    }
    let notes = start_notes(scene, settings, from);
    Ok(Plan {
        from,
        reported,
        shown,
        notes,
    })
}

/// The notes on the start and the stability orbit: unused by the exact method, or computed
/// at another speed than the first.
fn start_notes(scene: &Scene, settings: &SweepSettings, from: f64) -> Vec<SweepNote> {
    let mut notes = Vec::new();
    let per = scene.omega_per_speed;
    if matches!(scene.method, Method::PiecewiseExact(_)) {
        notes.extend(
            settings
                .start
                .as_ref()
                .map(|s| SweepNote::StartUnused(s.label.clone())),
        );
        if settings.orbit == Orbit::Harmonic {
            notes.push(SweepNote::OrbitUnused);
        }
    }
    if let Some((s, w)) = settings
        .start
        .as_ref()
        .and_then(|s| s.omega.map(|w| (s, w)))
    {
        if (w - from * per).abs() > 1e-9 * w {
            notes.push(SweepNote::StartSpeed {
                label: s.label.clone(),
                computed_at: w / per,
                from,
            });
        }
    }
    notes
}

/// The continuation of `scene` with `settings`.
fn continuation_of(scene: &Scene, settings: &SweepSettings) -> Continuation {
    let defaults = Continuation::default();
    let stability = defaults.stability.filter(|_| settings.stability);
    Continuation {
        max_step: settings.max_step,
        method: scene.method,
        tolerance: settings.tolerance.unwrap_or(defaults.tolerance),
        max_points: settings.max_points.unwrap_or(defaults.max_points),
        stability: stability.map(|f| FloquetOptions {
            orbit: settings.orbit,
            ..f
        }),
        error_estimate: settings.error_estimate,
        formulation: settings.formulation,
        cancel: settings.cancel.clone(),
        ..defaults
    }
}

/// The branch from `basis.omega()` to `to`, from the orbit `initial` if given; with the exact
/// piecewise method its solutions at `points` evenly spaced speeds.
fn main_branch(
    continuation: &Continuation,
    scene: &Scene,
    basis: HarmonicBasis,
    to: f64,
    initial: Option<&[Complex64]>,
    points: usize,
    progress: impl FnMut(f64),
) -> Result<Branch> {
    if matches!(continuation.method, Method::PiecewiseExact(_)) {
        let from = basis.omega();
        let values: Vec<f64> = (0..points)
            .map(|i| from + (to - from) * i as f64 / (points - 1) as f64)
            .collect();
        let build = |w| Ok((&scene.model, basis.with_omega(w)?));
        return crate::continuation::sweep_values(&values, build, continuation, progress);
    }
    continuation.run_from(&scene.model, basis, to, initial, progress)
}

/// The segments of a branch with automatic harmonics as one branch on the last H: their
/// points in order, each padded with zeros to the last H (exact: a point has no content
/// above its own H), the last segment's stop; with the basis of that H and the note of where
/// H changed (none where it did not).
fn joined(
    mut segments: Vec<Branch>,
    basis: HarmonicBasis,
) -> Result<(Branch, HarmonicBasis, Option<SweepNote>)> {
    let mut branch = segments.remove(0);
    let first = branch.harmonics;
    let mut changes = Vec::new();
    for s in segments {
        if let BranchStop::HarmonicsChanged { omega, harmonics } = branch.stop {
            changes.push((omega, harmonics));
        }
        branch.points.extend(s.points);
        branch.stop = s.stop;
    }
    let n = branch.dofs.len().max(1);
    let top = branch
        .points
        .iter()
        .map(|p| p.harmonics.len() / n)
        .max()
        .unwrap_or(1)
        .saturating_sub(1);
    for p in &mut branch.points {
        p.harmonics.resize((top + 1) * n, Complex64::default());
    }
    let ratio = top.max(1) as f64 / basis.harmonics().max(1) as f64;
    let samples = ((basis.samples() as f64 * ratio).ceil() as usize).max(4 * top + 1);
    let last = HarmonicBasis::new(basis.omega(), top)?
        .with_tail_correction_of(&basis)
        .with_subharmonic(basis.subharmonic())?
        .with_samples(samples)?;
    branch.harmonics = top;
    let note = (!changes.is_empty()).then_some(SweepNote::HarmonicsAlongBranch(first, changes));
    Ok((branch, last, note))
}

/// Why the stability asked for is not available ([`crate::stability::unavailable`]).
fn stability_unavailable(scene: &Scene, settings: &SweepSettings) -> Option<String> {
    crate::stability::unavailable(&scene.model).filter(|_| settings.stability)
}
