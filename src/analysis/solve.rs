//! One solve of a scene with everything `hbal solve` reports ([`solve()`]).
//!
//! The path taken: automatic harmonics where the scene asks for them (H raised until the
//! error estimate meets the tolerance, handed to the exact piecewise method at the cap where
//! that applies); the exact piecewise method where the scene names it; otherwise harmonic
//! balance at the scene's H with its method, and where that fails from the linear solution
//! the other solvers, the load homotopy and continuation in the speed (`fallback`, named in
//! [`SolveAnalysis::found_by`]), then the error estimate against 2H. A converged orbit gets
//! its Floquet multipliers where they are available (laws with memory only in small grounded
//! models); an unconverged iterate gets none.

use super::element_record::element_records;
use crate::continuation::{solve_with_fallbacks, Continuation};
use crate::scene::Scene;
use crate::solve::piecewise::{ExactExtremes, ExactSolution};
use crate::solve::{AutoHarmonics, ErrorEstimate, Level, Method, PiecewiseExact};
use crate::stability::Floquet;
use crate::{Error, Formulation, HarmonicBalance, Result, Solution};
use num_complex::Complex64;
use std::time::Instant;

/// What to do besides the scene's own settings.
#[derive(Debug, Clone, PartialEq)]
pub struct SolveSettings {
    /// Harmonics to start from, harmonic-major `Q[k · n + i]` on the scene's H (a fixed H
    /// only), and a label for the record (the file it came from).
    pub start: Option<(Vec<Complex64>, String)>,
    /// Compute the Floquet multipliers of a converged orbit (default `true`).
    pub stability: bool,
    /// Where the scene's method fails from the linear solution, try the other solvers, the
    /// load homotopy and continuation in the speed (default `true`).
    pub fallback: bool,
    /// How the harmonic balance holds the unknowns, automatic harmonics included (default
    /// [`Formulation::Auto`]: condensed where it pays).
    pub formulation: Formulation,
}

impl Default for SolveSettings {
    fn default() -> Self {
        Self {
            start: None,
            stability: true,
            fallback: true,
            formulation: Formulation::Auto,
        }
    }
}

/// The Floquet stability of the solution.
#[derive(Debug, Clone)]
pub enum StabilityOutcome {
    /// Not asked for, or no converged orbit to judge.
    NotComputed,
    /// Not available for this model (the reason).
    Unavailable(String),
    /// The multipliers.
    Computed(Floquet),
    /// The computation failed (the reason).
    Failed(String),
}

/// Automatic harmonics as they ran.
#[derive(Debug, Clone)]
pub struct AutoRecord {
    /// The settings (the scene's, with the analysis's formulation).
    pub settings: AutoHarmonics,
    /// Every level tried.
    pub levels: Vec<Level>,
    /// `true` where the tolerance was not reached (at the cap, or where a level failed).
    pub capped: bool,
    /// Where a level after the first failed: why (the solution is the last level's that
    /// succeeded).
    pub stopped: Option<String>,
}

/// Something the user should read beside the numbers.
#[derive(Debug, Clone, PartialEq)]
pub enum SolveNote {
    /// The start harmonics were not used: the exact piecewise solution needs none.
    StartUnused,
    /// A coefficient jumps in time and the harmonics above H are mass-dominated: the tail
    /// correction, left to its default (off at a fixed H), would improve `kept_harmonics`.
    TailCorrection {
        /// The estimated error of the harmonics 0..H.
        kept_harmonics: f64,
        /// H.
        harmonics: usize,
    },
    /// The scene is linear with piecewise-constant coefficients: the exact piecewise method
    /// gives the harmonics and the extremes exactly.
    PiecewiseExactApplies {
        /// The estimated error of the harmonics 0..H.
        kept_harmonics: f64,
    },
}

/// Everything one solve of a scene gives ([`solve()`]); its serde form is `hbal solve --json`.
#[derive(Debug, Clone)]
pub struct SolveAnalysis {
    /// The scene's file (or name).
    pub file: String,
    /// The solution (converged or the last iterate).
    pub solution: Solution,
    /// The method that answered (`piecewise_exact` after a switch at the cap).
    pub method: String,
    /// Automatic harmonics handed over to the exact piecewise solution at the cap.
    pub switched_to_exact: bool,
    /// The path that found the orbit where the scene's method alone did not.
    pub found_by: Option<String>,
    /// The start harmonics' label, where they were used.
    pub start: Option<String>,
    /// The error estimate (`None` for an unconverged iterate; the reason where it failed).
    pub estimate: Option<std::result::Result<ErrorEstimate, String>>,
    /// Automatic harmonics as they ran.
    pub auto: Option<AutoRecord>,
    /// The exact piecewise solution's extremes from its closed form in time, where it answered.
    pub extremes: Option<ExactExtremes>,
    /// `max |q_i|` of every DOF (from the closed form where there is one).
    pub max_abs: Vec<f64>,
    /// Every element's output (the reason where they could not be computed).
    pub elements: std::result::Result<Vec<crate::report::ElementOutput>, String>,
    /// The stability of the orbit.
    pub stability: StabilityOutcome,
    /// Notes for the user.
    pub notes: Vec<SolveNote>,
    /// The scene's fundamental order relative to its reference speed.
    pub fundamental_order: f64,
    /// Wall times of the solve (with the estimate) and of the stability, s.
    pub seconds: (f64, f64),
    /// Names of the worst quantity and the worst force of the estimate (for the record).
    pub(crate) quantity_names: (Option<String>, Option<String>),
    /// The exact solution, for its time series.
    pub exact: Option<ExactSolution>,
}

impl SolveAnalysis {
    /// `Some(stable)` where the multipliers were computed.
    pub fn stable(&self) -> Option<bool> {
        match &self.stability {
            StabilityOutcome::Computed(f) => Some(f.is_stable()),
            _ => None,
        }
    }

    /// `true` where automatic harmonics stopped at the cap above the tolerance.
    pub fn capped(&self) -> bool {
        self.auto.as_ref().is_some_and(|a| a.capped)
    }

    /// The exit code of the contract: 0 for a converged orbit with its stability (where
    /// asked) and its tolerance (automatic harmonics) met, 1 otherwise (results marked).
    pub fn exit_code(&self) -> u8 {
        let failed = matches!(self.stability, StabilityOutcome::Failed(_));
        if self.solution.is_converged() && !failed && !self.capped() {
            0
        } else {
            1
        }
    }
}

/// Solves `scene` with `settings` (module documentation).
///
/// # Errors
/// Bad input (a start with automatic harmonics, what the model or basis refuses) and a solve
/// that fails outright; a solve that ends unconverged is a result, marked.
pub fn solve(scene: &Scene, settings: &SolveSettings) -> Result<SolveAnalysis> {
    scene.require_operating_point("solve")?;
    if let Some((q, label)) = &settings.start {
        check_start(scene, q, label)?;
    }
    let started = Instant::now();
    let mut notes = Vec::new();
    let mut found_by = None;
    let mut exact = None;
    let mut auto = None;
    let mut switched = false;
    let mut start = settings.start.as_ref().map(|(_, label)| label.clone());
    // The solve's wall time: the estimate of a fixed-H solve is not part of it (as before the
    // analysis layer, and as docs/scenes.md says); automatic harmonics include theirs.
    let (solution, estimate, solve_seconds) = match scene.auto {
        Some(mut settings_auto) => {
            settings_auto.formulation = settings.formulation;
            if settings.start.is_some() {
                return Err(Error::InvalidOptions {
                    option: "--start".into(),
                    reason: "needs a fixed H: give --harmonics N (automatic harmonics start from the linear solution)".into(),
                });
            }
            let a =
                crate::solve::solve_auto(&scene.model, scene.basis, &scene.method, settings_auto)?;
            found_by = a.found_by;
            exact = a.exact;
            switched = a.switched_to_exact;
            auto = Some(AutoRecord {
                settings: settings_auto,
                levels: a.levels,
                capped: a.capped,
                stopped: a.stopped,
            });
            (
                a.solution,
                Some(Ok(a.estimate)),
                started.elapsed().as_secs_f64(),
            )
        }
        None if matches!(scene.method, Method::PiecewiseExact(_)) => {
            if start.take().is_some() {
                notes.push(SolveNote::StartUnused);
            }
            let e = PiecewiseExact::new().solve_exact(&scene.model, &scene.basis)?;
            let out = (
                e.solution.clone(),
                Some(Ok(e.estimate)),
                started.elapsed().as_secs_f64(),
            );
            exact = Some(e);
            out
        }
        None => {
            let hb =
                HarmonicBalance::with_formulation(&scene.model, scene.basis, settings.formulation)?;
            let continuation = Continuation {
                method: scene.method,
                formulation: settings.formulation,
                ..Default::default()
            };
            let initial = settings.start.as_ref().map(|(q, _)| q.as_slice());
            let (solution, how) = if settings.fallback {
                solve_with_fallbacks(&scene.model, scene.basis, &continuation, initial)?
            } else {
                let mut ws = hb.workspace();
                (scene.method.solve(&hb, initial, &mut ws)?, None)
            };
            found_by = how;
            let seconds = started.elapsed().as_secs_f64();
            let estimate = solution.is_converged().then(|| {
                crate::solve::estimate_error(&scene.model, &solution).map_err(|e| e.to_string())
            });
            if let Some(Ok(e)) = &estimate {
                notes.extend(tail_correction_note(scene, &hb, e));
            }
            (solution, estimate, seconds)
        }
    };
    if let Some(Ok(e)) = &estimate {
        notes.extend(piecewise_note(scene, e));
    }
    let started = Instant::now();
    let stability = stability(scene, settings, &solution, exact.as_ref());
    let stability_seconds = started.elapsed().as_secs_f64();
    let extremes = exact.as_ref().map(ExactSolution::extremes);
    let max_abs = match &extremes {
        Some(x) => x.max_abs(),
        None => solution.max_abs_all(),
    };
    let elements = element_records(&scene.model, &solution, extremes.as_ref());
    let quantity_names = match &estimate {
        Some(Ok(e)) => (
            e.worst_quantity.map(|q| q.quantity.name(&scene.model)),
            e.worst_force.map(|q| q.quantity.name(&scene.model)),
        ),
        _ => (None, None),
    };
    Ok(SolveAnalysis {
        file: scene.file.clone(),
        method: if switched {
            "piecewise_exact".into()
        } else {
            scene.method.name().into()
        },
        solution,
        switched_to_exact: switched,
        found_by,
        start: start.filter(|_| exact.is_none()),
        estimate,
        auto,
        extremes,
        max_abs,
        elements,
        stability,
        notes,
        fundamental_order: scene.fundamental_order,
        seconds: (solve_seconds, stability_seconds),
        quantity_names,
        exact,
    })
}

/// Checks start harmonics before any work: `n (H + 1)` of them, each part finite and at most
/// 1e100 in magnitude, so a start that would overflow the residual is bad input.
pub(super) fn check_start(scene: &Scene, q: &[Complex64], label: &str) -> Result<()> {
    let n = scene.model.n_dofs();
    let want = n * (scene.basis.harmonics() + 1);
    let bad = |reason: String| Error::InvalidOptions {
        option: "--start".into(),
        reason: format!("{label}: {reason}"),
    };
    if q.len() != want {
        return Err(bad(format!(
            "{} harmonics given, {want} expected (n (H + 1) = {n} ({}))",
            q.len(),
            scene.basis.harmonics() + 1
        )));
    }
    let dofs = scene.model.dof_names();
    if let Some((j, v)) = q.iter().enumerate().find(|(_, v)| {
        !(v.re.abs() <= crate::error::MAX_MAGNITUDE && v.im.abs() <= crate::error::MAX_MAGNITUDE)
    }) {
        return Err(bad(format!(
            "harmonic {} of `{}` is {:.3e} {:+.3e}i: each part must be finite and at most 1e100 in magnitude",
            j / n,
            dofs[j % n],
            v.re,
            v.im
        )));
    }
    Ok(())
}

/// The stability of a converged orbit where it is asked for and available.
fn stability(
    scene: &Scene,
    settings: &SolveSettings,
    solution: &Solution,
    exact: Option<&ExactSolution>,
) -> StabilityOutcome {
    if !settings.stability {
        return StabilityOutcome::NotComputed;
    }
    // Laws with memory in a large or free-free model, hysteretic damping: no multipliers
    // rather than wrong ones.
    if let Some(why) = crate::stability::unavailable(&scene.model) {
        return StabilityOutcome::Unavailable(format!("stability {why}"));
    }
    if !solution.is_converged() {
        return StabilityOutcome::NotComputed;
    }
    let floquet = match exact {
        Some(e) => Ok(e.floquet()),
        None => solution.stability(&scene.model),
    };
    match floquet {
        Ok(f)
            if f.multipliers
                .iter()
                .all(|m| m.re.is_finite() && m.im.is_finite()) =>
        {
            StabilityOutcome::Computed(f)
        }
        Ok(_) => StabilityOutcome::Failed("non-finite Floquet multiplier".into()),
        Err(e) => StabilityOutcome::Failed(e.to_string()),
    }
}

/// The tail-correction note where it is left to its default and would apply at this H.
fn tail_correction_note(
    scene: &Scene,
    hb: &HarmonicBalance,
    e: &ErrorEstimate,
) -> Option<SolveNote> {
    let unset = scene.basis.tail_correction_setting().is_none();
    (e.kept_harmonics > 1e-6 && unset && hb.tail_correction_would_apply()).then(|| {
        SolveNote::TailCorrection {
            kept_harmonics: e.kept_harmonics,
            harmonics: scene.basis.harmonics(),
        }
    })
}

/// The note on the exact piecewise method where harmonic balance leaves the harmonics above
/// 1e-6 and the scene admits it.
fn piecewise_note(scene: &Scene, e: &ErrorEstimate) -> Option<SolveNote> {
    (e.kept_harmonics > 1e-6
        && !matches!(scene.method, Method::PiecewiseExact(_))
        && PiecewiseExact::check(&scene.model).is_ok())
    .then_some(SolveNote::PiecewiseExactApplies {
        kept_harmonics: e.kept_harmonics,
    })
}

impl std::fmt::Display for SolveNote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolveNote::StartUnused => write!(
                f,
                "the start is not used: the exact piecewise solution needs no start"
            ),
            SolveNote::TailCorrection {
                kept_harmonics,
                harmonics,
            } => write!(
                f,
                "the harmonics 0..H are estimated {kept_harmonics:.1e} off; a coefficient jumps in time and the harmonics above H = {harmonics} are mass-dominated: `tail_correction = true` in [harmonics] (or `--harmonics auto:harmonics`) adds their coupling to the kept ones (the two-shaft model at 6000 rpm: 2.7e-4 -> 8.9e-7 at H = 32)"
            ),
            SolveNote::PiecewiseExactApplies { kept_harmonics } => write!(
                f,
                "the harmonics 0..H are estimated {kept_harmonics:.1e} off; this scene is linear with piecewise-constant coefficients: `--method piecewise_exact` gives them, and the extremes in time, exactly"
            ),
        }
    }
}
