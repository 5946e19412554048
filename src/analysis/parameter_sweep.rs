//! A sweep of one numeric scene field ([`parameter_sweep()`], `hbal sweep --parameter`):
//! warm-started Newton over evenly spaced values (it does not follow folds), with stability,
//! on the scene's basis or the overrides' (automatic harmonics: H and N chosen at the first
//! value and kept).

use super::observer::Observer;
use super::output_choice::reported_dofs;
use crate::continuation::{Branch, BranchStop, Cancel, Continuation};
use crate::scene::{set_parameter, Overrides, Scene};
use crate::solve::AutoHarmonics;
use crate::stability::FloquetOptions;
use crate::{Error, HarmonicBasis, Result};
use serde_json::{json, Value};
use std::time::Instant;

/// What a parameter sweep does.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterSweepSettings {
    /// The field, e.g. `elements[0].alpha` or `loads[1].cos`.
    pub parameter: String,
    /// The first value.
    pub from: f64,
    /// The last value.
    pub to: f64,
    /// The number of evenly spaced values, at least 2.
    pub points: usize,
    /// Floquet stability of every point.
    pub stability: bool,
    /// Harmonics, samples and formulation beside the scene's (a method or tolerance is
    /// refused: every point is Newton from the previous one).
    pub overrides: Overrides,
    /// The DOFs reported in full ([`reported_dofs`](super::reported_dofs)).
    pub dofs: Option<String>,
    /// Set from outside to stop after the current value (the points so far are kept).
    pub cancel: Cancel,
}

/// Automatic harmonics at the first value, kept for the others.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParameterAuto {
    /// The settings.
    pub settings: AutoHarmonics,
    /// The H chosen.
    pub harmonics: usize,
    /// Its error estimate in what the settings control.
    pub estimate: f64,
    /// Above the tolerance at the cap.
    pub capped: bool,
}

/// Everything a parameter sweep gives; its serde form is `hbal sweep --parameter --json`.
#[derive(Debug, Clone)]
pub struct ParameterSweepAnalysis {
    /// The scene's file.
    pub file: String,
    /// The settings it ran with.
    pub settings: ParameterSweepSettings,
    /// The branch (`parameter` of each point the field's value).
    pub branch: Branch,
    /// The DOFs reported in full.
    pub reported: Vec<usize>,
    /// The scene's fundamental order of its reference speed.
    pub fundamental_order: f64,
    /// Automatic harmonics at the first value, where on.
    pub auto: Option<ParameterAuto>,
    /// Wall time, s.
    pub seconds: f64,
}

/// Sweeps the field `settings.parameter` of the scene `document` (parsed, from `file`).
///
/// # Errors
/// Bad input before any work: a method or tolerance override, non-finite ends, fewer than 2
/// points, a field that does not exist or takes whole numbers only, a field that changes the
/// model's DOFs, a scene invalid at the first value. A value where the scene becomes invalid
/// later ends the branch there (a result, marked).
pub fn parameter_sweep(
    document: &Value,
    file: &str,
    settings: &ParameterSweepSettings,
    observer: &mut dyn Observer,
) -> Result<ParameterSweepAnalysis> {
    let first = check(document, file, settings)?;
    let reported = reported_dofs(&first.model, settings.dofs.as_deref())?;
    let (auto, chosen) = match first.auto {
        Some(settings_auto) => {
            let a =
                crate::solve::solve_auto(&first.model, first.basis, &first.method, settings_auto)?;
            let record = ParameterAuto {
                settings: settings_auto,
                harmonics: a.solution.basis().harmonics(),
                estimate: settings_auto.control.of(&a.estimate),
                capped: a.capped,
            };
            (Some(record), Some(*a.solution.basis()))
        }
        None => (None, None),
    };
    let values = values(settings);
    let continuation = Continuation {
        stability: settings.stability.then(FloquetOptions::default),
        formulation: settings.overrides.formulation,
        cancel: settings.cancel.clone(),
        ..Continuation::default()
    };
    let started = Instant::now();
    let build = |p: f64| {
        let scene = scene_at(document, file, settings, p).map_err(|e| Error::Solver {
            reason: e.to_string(),
        })?;
        let basis = match &chosen {
            Some(c) => HarmonicBasis::new(scene.basis.omega(), c.harmonics())?
                .with_tail_correction_of(c)
                .with_samples(c.samples())?,
            None => scene.basis,
        };
        Ok((scene.model, basis))
    };
    let progress = |f: f64| observer.progress(f);
    let branch = crate::continuation::sweep_values(&values, build, &continuation, progress)?;
    Ok(ParameterSweepAnalysis {
        file: file.to_string(),
        settings: settings.clone(),
        branch,
        reported,
        fundamental_order: first.fundamental_order,
        auto,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// Checks `settings` against the scene `document` as [`parameter_sweep()`] does before any
/// work (a front end that prepares output files calls it first).
///
/// # Errors
/// What [`parameter_sweep()`] refuses as bad input.
pub fn check_parameter_sweep(
    document: &Value,
    file: &str,
    settings: &ParameterSweepSettings,
) -> Result<()> {
    let first = check(document, file, settings)?;
    reported_dofs(&first.model, settings.dofs.as_deref()).map(|_| ())
}

/// The evenly spaced values.
fn values(settings: &ParameterSweepSettings) -> Vec<f64> {
    let (from, to, n) = (settings.from, settings.to, settings.points);
    (0..n)
        .map(|i| from + (to - from) * i as f64 / (n - 1) as f64)
        .collect()
}

/// The scene `document` with the field at `value` and the overrides applied.
fn scene_at(
    document: &Value,
    file: &str,
    settings: &ParameterSweepSettings,
    value: f64,
) -> Result<Scene> {
    let mut d = document.clone();
    set_parameter(&mut d, &settings.parameter, value).map_err(|e| Error::InvalidOptions {
        option: "--parameter".into(),
        reason: e,
    })?;
    let mut scene = Scene::from_value(d, file)?;
    settings.overrides.apply(&mut scene)?;
    Ok(scene)
}

/// The settings checked against the scene before any work; the scene at the first value.
fn check(document: &Value, file: &str, settings: &ParameterSweepSettings) -> Result<Scene> {
    let bad = |option: &str, reason: String| Error::InvalidOptions {
        option: option.into(),
        reason,
    };
    let speed_only = "applies to speed sweeps, not to a --parameter sweep";
    if settings.overrides.method.is_some() {
        return Err(bad("--method", speed_only.into()));
    }
    if settings.overrides.tolerance.is_some() {
        return Err(bad("--tolerance", speed_only.into()));
    }
    let finite = |x: f64| x.is_finite() && x.abs() <= crate::error::MAX_MAGNITUDE;
    if !(finite(settings.from) && finite(settings.to)) || settings.points < 2 {
        return Err(bad(
            "--from",
            "and --to must be finite (at most 1e100) and --points >= 2".into(),
        ));
    }
    let name = &settings.parameter;
    let changes_dofs = |name: &str| {
        format!("{name} changes the model's DOFs: a sweep follows one model's response; sweep a field that keeps them")
    };
    if name == "dofs" || name.starts_with("dofs.") || name.starts_with("dofs[") {
        return Err(bad("--parameter", changes_dofs(name)));
    }
    let first = scene_at(document, file, settings, settings.from)?;
    first.require_operating_point("sweep")?;
    if let Some((i, x)) = values(settings)
        .into_iter()
        .enumerate()
        .find(|(_, x)| x.fract() != 0.0)
    {
        match scene_at(document, file, settings, x) {
            Err(Error::Scene(e)) if e.message.starts_with("invalid type: floating point") => {
                return Err(bad("--parameter", format!(
                    "{name} takes whole numbers, and value {} ({x}) is not one: choose --from, --to and --points so that every value is whole",
                    i + 1
                )))
            }
            _ => {}
        }
    }
    if let Ok(last) = scene_at(document, file, settings, settings.to) {
        if last.model.dof_names() != first.model.dof_names() {
            return Err(bad("--parameter", changes_dofs(name)));
        }
    }
    Ok(first)
}

impl ParameterSweepAnalysis {
    /// The exit code: 0 where every value was solved, 1 otherwise (the points kept, marked).
    pub fn exit_code(&self) -> u8 {
        u8::from(self.branch.stop != BranchStop::Reached)
    }

    /// The JSON record (what `Serialize` writes).
    pub fn to_json(&self) -> Value {
        let points: Vec<Value> = self
            .branch
            .points
            .iter()
            .map(|p| {
                let f = p.floquet.as_ref();
                json!({
                    "parameter": p.parameter,
                    "stable": p.stable(),
                    "bifurcation": p.bifurcation.map(|b| format!("{b:?}")),
                    "max_abs": p.max_abs,
                    "residual": p.residual,
                    "truncation": p.truncation,
                    "multipliers": f.map(|f| f.pairs()),
                    "multipliers_abs": f.map(|f| f.moduli()),
                    "neutral": f.map(|f| f.neutral),
                    "orbit_correction": f.map(|f| f.orbit_correction),
                })
            })
            .collect();
        let b = &self.branch;
        json!({
            "schema_version": super::SCHEMA_VERSION,
            "scene": self.file, "parameter": self.settings.parameter, "harmonics": b.harmonics,
            "stop": b.stop.to_string(), "reached": b.stop == BranchStop::Reached,
            "seconds": self.seconds, "dofs": b.dofs, "points": points,
        })
    }
}

impl serde::Serialize for ParameterSweepAnalysis {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.to_json().serialize(s)
    }
}
