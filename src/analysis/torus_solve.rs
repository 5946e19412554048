//! One operating point of a scene on several base frequencies ([`crate::torus`]): the solve
//! (with automatic caps where the scene asks), each base's truncation estimate, the spectra
//! of every element coordinate and DOF as labelled lines, and the stability statement.

use super::torus_lines::{dof_spectra, spectrum, Spectrum};
use crate::error::{Error, Result};
use crate::scene::{Scene, TorusPlan};
use crate::torus::{
    AutoCapsOutcome, CapsLevel, IndexSet, NewtonKrylov, TorusBalance, TorusSolution, TorusStability,
};
use num_complex::Complex64;

/// Lines kept per spectrum.
pub const TOP_LINES: usize = 12;

/// What a torus solve is asked.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TorusSolveSettings {
    /// The speed in the scene's unit (default: the scene's).
    pub speed: Option<f64>,
}

/// One base as solved.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BaseRecord {
    /// Its name (`engine`, `shaft`, or a gear stage's).
    pub name: String,
    /// Its order of the speed.
    pub order: f64,
    /// Its frequency at the speed, Hz (`None` in a sweep).
    pub hz: Option<f64>,
    /// Its cap.
    pub cap: usize,
    /// Its grid points.
    pub samples: usize,
    /// Its truncation estimate (relative to the alternating response; `None`: not estimated).
    pub estimate: Option<f64>,
}

/// A solved point of a torus scene (its serde form is `hbal solve --json` of such a scene).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TorusSolveAnalysis {
    /// The speed, in `speed_unit`.
    pub speed: f64,
    /// `rpm`, `hz` or `rad_s`.
    pub speed_unit: String,
    /// Why the scene is on the torus.
    pub why: String,
    /// The bases.
    pub bases: Vec<BaseRecord>,
    /// Lines of the index set.
    pub lines: usize,
    /// Whether Newton–Krylov reached the tolerance.
    pub converged: bool,
    /// The relative residual reached.
    pub relative_residual: f64,
    /// Automatic caps: the levels, and why they stopped short of the tolerance (`None`:
    /// reached, or fixed caps).
    pub levels: Vec<CapsLevel>,
    /// Why automatic caps stopped above the tolerance.
    pub caps_stopped: Option<String>,
    /// Every element coordinate's spectrum (a gear stage's: its transmission error, m).
    pub elements: Vec<Spectrum>,
    /// Every element's force spectrum (a gear stage's: its mesh force, N).
    pub forces: Vec<Spectrum>,
    /// Every DOF's spectrum.
    pub dofs: Vec<Spectrum>,
    /// The stability statement.
    pub stability: TorusStability,
    /// The solution: every DOF's lines.
    pub solution: TorusSolution,
    /// Every element coordinate's lines (name, `U_k` on the solution's lines; not in the
    /// JSON, which has the strongest in `elements`).
    #[serde(skip)]
    pub element_lines: Vec<(String, Vec<Complex64>)>,
    /// Every element's force lines (name, `F_k`; not in the JSON, which has the strongest in
    /// `forces`).
    #[serde(skip)]
    pub force_lines: Vec<(String, Vec<Complex64>)>,
}

impl TorusSolveAnalysis {
    /// 0 if converged (and automatic caps reached their tolerance), else 1.
    pub fn exit_code(&self) -> u8 {
        u8::from(!self.converged || self.caps_stopped.is_some())
    }

    /// The JSON of `hbal solve --json`.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
    }
}

/// The plan of a torus scene, or the error for a scene on one fundamental.
pub(super) fn plan_of<'s>(scene: &'s Scene, analysis: &str) -> Result<&'s TorusPlan> {
    if !scene.operating_point {
        scene.require_operating_point(analysis)?;
    }
    scene.torus.as_ref().ok_or_else(|| Error::InvalidElement {
        context: format!("torus {analysis}"),
        reason: "the scene is solved on one fundamental (`harmonics.bases = \"torus\"` puts it on several)".into(),
    })
}

/// Solves a scene on several base frequencies at its speed (or `settings.speed`).
///
/// ```
/// use hbal::analysis::{torus_solve, TorusSolveSettings};
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/two_stage_train_torus.toml");
/// let scene = hbal::scene::Scene::load(std::path::Path::new(path)).unwrap();
/// let a = torus_solve(&scene, &TorusSolveSettings::default()).unwrap();
/// assert!(a.converged);
/// assert_eq!(a.bases.len(), 3); // engine, stage1, stage2
/// // Stage 1's strongest transmission-error line: its mesh's third harmonic (order 69).
/// assert_eq!(a.elements[0].lines[0].label, "3 stage1");
/// ```
pub fn torus_solve(scene: &Scene, settings: &TorusSolveSettings) -> Result<TorusSolveAnalysis> {
    let plan = plan_of(scene, "solve")?;
    let speed = settings.speed.unwrap_or(plan.speed);
    let omega = speed * plan.rad_s_per_speed;
    crate::harmonic::HarmonicBasis::new(omega, 0).map_err(|_| Error::InvalidOptions {
        option: "speed".into(),
        reason: format!("must be finite and > 0, got {speed} {}", scene.speed_unit),
    })?;
    scene.model.check_load_speeds(omega, omega)?;
    let tm = plan.bind(&scene.model)?;
    let solver = NewtonKrylov {
        tolerance: plan.tolerance,
        ..NewtonKrylov::default()
    };
    let outcome = match &plan.auto {
        Some(auto) => auto.solve(
            &tm,
            &plan.caps,
            &plan.samples,
            plan.truncation,
            omega,
            &solver,
        )?,
        None => {
            let set: IndexSet = plan.index_set()?;
            let hb = TorusBalance::new(tm, set, &plan.samples, omega)?;
            AutoCapsOutcome {
                solution: solver.solve(&hb, None)?,
                caps: plan.caps.clone(),
                samples: plan.samples.clone(),
                truncation: plan.truncation,
                levels: Vec::new(),
                stopped: None,
            }
        }
    };
    // The elements' forces on the last level's lines.
    let set = IndexSet::new(&plan.bases, &outcome.caps, outcome.truncation)?;
    let hb = TorusBalance::new(plan.bind(&scene.model)?, set, &outcome.samples, omega)?;
    let forces = hb.element_force_lines(&outcome.solution)?;
    Ok(analysis_of(scene, plan, speed, outcome, forces))
}

/// The analysis record of a solved outcome.
fn analysis_of(
    scene: &Scene,
    plan: &TorusPlan,
    speed: f64,
    outcome: AutoCapsOutcome,
    forces: Vec<Vec<Complex64>>,
) -> TorusSolveAnalysis {
    let sol = outcome.solution;
    let names = scene.model.elements().iter().map(|e| e.name());
    let force_spectra = names
        .zip(&forces)
        .map(|(name, f)| spectrum(&sol, name, f, TOP_LINES))
        .collect();
    let element_lines: Vec<(String, Vec<Complex64>)> = scene
        .model
        .elements()
        .iter()
        .map(|e| (e.name().to_string(), sol.coordinate_lines(e.weights())))
        .collect();
    let force_lines = scene
        .model
        .elements()
        .iter()
        .map(|e| e.name().to_string())
        .zip(forces)
        .collect();
    let bases = (0..plan.bases.len())
        .map(|b| BaseRecord {
            name: plan.bases.names()[b].clone(),
            order: plan.bases.ratios()[b],
            hz: Some(plan.bases.ratios()[b] * sol.omega / std::f64::consts::TAU),
            cap: outcome.caps[b],
            samples: outcome.samples[b],
            estimate: sol.truncation[b],
        })
        .collect();
    TorusSolveAnalysis {
        speed,
        speed_unit: scene.speed_unit.to_string(),
        why: plan.why.clone(),
        bases,
        lines: sol.indices.len(),
        converged: sol.converged,
        relative_residual: sol.relative_residual,
        levels: outcome.levels,
        caps_stopped: outcome.stopped,
        elements: element_lines
            .iter()
            .map(|(name, q)| spectrum(&sol, name, q, TOP_LINES))
            .collect(),
        forces: force_spectra,
        force_lines,
        element_lines,
        dofs: dof_spectra(&sol, TOP_LINES),
        stability: TorusStability::quasi_periodic(),
        solution: sol,
    }
}
