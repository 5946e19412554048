//! Every solver (or the named ones) on one scene against the time-domain reference
//! ([`compare()`], `hbal compare`): iterations, wall time, and the error of each result
//! against the time domain, as a whole and per quantity; with automatic harmonics every
//! method runs at the H they choose.
//!
//! The time-domain reference starts on the first converged HB orbit (from rest if none): a
//! gear pair with backlash can have coexisting orbits, and a run from rest may find another
//! one. Its error then measures the HB orbit, and grows if that orbit is unstable.

use crate::compare::{model_relative_error, QuantityError};
use crate::scene::{Overrides, Scene};
use crate::solve::PiecewiseExact;
use crate::timesim::{TimeResponse, TimeSimulation};
use crate::{Error, Formulation, HarmonicBalance, HarmonicBasis, Result, Solution};
use serde_json::{json, Value};
use std::time::Instant;

/// What to compare.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CompareSettings {
    /// The methods by name (default: every method that applies; the exact piecewise method
    /// only to linear scenes with piecewise-constant coefficients).
    pub methods: Option<Vec<String>>,
    /// The solvers' relative residual tolerance (default: the scene's).
    pub tolerance: Option<f64>,
    /// How the harmonic balance holds the unknowns.
    pub formulation: Formulation,
}

/// One method's result against the time domain.
#[derive(Debug, Clone)]
pub struct MethodComparison {
    /// The method's name.
    pub method: String,
    /// Its wall time, s.
    pub seconds: f64,
    /// Its solution (converged or the last iterate).
    pub solution: Solution,
    /// The relative error of its harmonics 0..H against the time domain's.
    pub error: f64,
    /// The worst DOF or element coordinate against the time domain's samples (dynamic part,
    /// of its range; all the time domain's harmonics), where computed.
    pub worst_quantity: Option<QuantityError>,
}

/// Automatic harmonics at the scene's speed, the H every method ran at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompareAuto {
    /// The settings.
    pub settings: crate::solve::AutoHarmonics,
    /// Its error estimate in what the settings control.
    pub estimate: f64,
    /// Above the tolerance at the cap.
    pub capped: bool,
}

/// Everything `hbal compare` reports.
#[derive(Debug, Clone)]
pub struct CompareAnalysis {
    /// The scene's file.
    pub file: String,
    /// The basis every method ran on.
    pub basis: HarmonicBasis,
    /// Automatic harmonics, where on.
    pub auto: Option<CompareAuto>,
    /// Every method's result, in order.
    pub methods: Vec<MethodComparison>,
    /// The time-domain reference.
    pub time_domain: TimeResponse,
    /// `true` where it started on a converged HB orbit (else from rest).
    pub started_on_hb_orbit: bool,
    /// Names of the worst quantities (parallel to `methods`).
    quantity_names: Vec<Option<String>>,
}

/// Compares the methods on `scene` (module documentation).
///
/// # Errors
/// An unknown method or a bad tolerance (bad input), a model the harmonic balance refuses,
/// a method that fails outright, a time integration that fails.
pub fn compare(scene: &Scene, settings: &CompareSettings) -> Result<CompareAnalysis> {
    scene.require_operating_point("compare")?;
    let overrides = Overrides {
        tolerance: settings.tolerance,
        formulation: settings.formulation,
        ..Overrides::default()
    };
    let names: Vec<String> = match &settings.methods {
        Some(names) => names.clone(),
        None => crate::scene::METHODS
            .iter()
            .filter(|&&m| m != "piecewise_exact" || PiecewiseExact::check(&scene.model).is_ok())
            .map(|m| m.to_string())
            .collect(),
    };
    let methods = names
        .iter()
        .map(|name| overrides.with_tolerance(scene.method_named(name)?))
        .collect::<Result<Vec<_>>>()?;
    let mut basis = scene.basis;
    let mut auto = None;
    if let Some(a) = scene.auto {
        let solved = crate::solve::solve_auto(&scene.model, basis, &scene.method, a)?;
        basis = *solved.solution.basis();
        auto = Some(CompareAuto {
            settings: a,
            estimate: a.control.of(&solved.estimate),
            capped: solved.capped,
        });
    }
    let hb = HarmonicBalance::with_formulation(&scene.model, basis, settings.formulation)?;
    let mut solved = Vec::new();
    for (name, method) in names.iter().zip(methods) {
        let mut ws = hb.workspace();
        let start = Instant::now();
        let sol = method.solve(&hb, None, &mut ws)?;
        solved.push((name.clone(), start.elapsed().as_secs_f64(), sol));
    }
    let (time_domain, started_on_hb_orbit) = reference(scene, &basis, &solved)?;
    let methods: Vec<MethodComparison> = solved
        .into_iter()
        .map(|(method, seconds, solution)| {
            against(scene, &basis, &time_domain, method, seconds, solution)
        })
        .collect();
    let quantity_names = methods
        .iter()
        .map(|m| m.worst_quantity.map(|q| q.quantity.name(&scene.model)))
        .collect();
    Ok(CompareAnalysis {
        file: scene.file.clone(),
        basis,
        auto,
        methods,
        time_domain,
        started_on_hb_orbit,
        quantity_names,
    })
}

/// The time-domain reference, from the first converged orbit of `solved` (else from rest).
fn reference(
    scene: &Scene,
    basis: &HarmonicBasis,
    solved: &[(String, f64, Solution)],
) -> Result<(TimeResponse, bool)> {
    let n = scene.model.n_dofs();
    let start_state = solved
        .iter()
        .find(|s| s.2.is_converged())
        .map(|(_, _, sol)| {
            let q = (0..n).map(|i| sol.displacement(i, 0.0)).collect::<Vec<_>>();
            let v = (0..n).map(|i| sol.velocity(i, 0.0)).collect::<Vec<_>>();
            (q, v)
        });
    let from_orbit = start_state.is_some();
    check_reference_cost(scene, basis, solved)?;
    let td = TimeSimulation {
        rtol: 1e-10,
        steady_tolerance: 1e-8,
        // Its harmonics come from samples: 1024 put 8e-7 into the two-shaft model's at
        // 600 rpm (the ringing of its stiffness jumps near harmonic 77), 4096 3e-9.
        samples: (4 * basis.harmonics() + 4).next_power_of_two().max(4096),
        initial: start_state,
        // Started on the HB orbit it settles in tens of periods; a bounded effort from rest
        // (a scene whose contact never closes drifts for 1e5): then marked not converged.
        max_periods: MAX_REFERENCE_PERIODS,
        max_steps: Some(MAX_REFERENCE_STEPS),
        ..TimeSimulation::default()
    }
    .run(&scene.model, basis.omega())
    .map_err(|e| match e {
        Error::TimeIntegration { reason } => Error::TimeIntegration {
            reason: format!("{reason} (the time-domain reference)"),
        },
        other => other,
    })?;
    Ok((td, from_orbit))
}

/// Most periods of the time-domain reference.
const MAX_REFERENCE_PERIODS: usize = 5000;

/// Most integrator steps of the time-domain reference (about a minute for a small model).
const MAX_REFERENCE_STEPS: usize = 2_000_000;

/// Most integrator steps per period the time-domain reference may need by its stiffness.
const MAX_STEPS_PER_PERIOD: f64 = 1e5;

/// Refuses a time-domain reference too stiff for its explicit integration before any of it:
/// DOP853's stable step is about `5/λ`, `λ` the fastest rate along the first solution's orbit
/// (Gershgorin's bound with every element at its largest tangent).
fn check_reference_cost(
    scene: &Scene,
    basis: &HarmonicBasis,
    solved: &[(String, f64, Solution)],
) -> Result<()> {
    let Some(first) = solved
        .iter()
        .find(|s| s.2.is_converged())
        .or(solved.first())
    else {
        return Ok(());
    };
    let Some(rate) = crate::stability::fastest_rate(&scene.model, &first.2) else {
        return Ok(());
    };
    let steps = rate * basis.period() / 5.0;
    if steps <= MAX_STEPS_PER_PERIOD {
        return Ok(());
    }
    Err(Error::TimeIntegration {
        reason: format!(
            "the time-domain reference would need at least {steps:.1e} steps per period (the limit {MAX_STEPS_PER_PERIOD:.0e}): the fastest motion decays or turns at {rate:.1e} 1/s over a period of {:.2e} s; check the damping, stiffness and loads for a unit mistake",
            basis.period()
        ),
    })
}

/// One method's solution measured against the time domain `td`.
fn against(
    scene: &Scene,
    basis: &HarmonicBasis,
    td: &TimeResponse,
    method: String,
    seconds: f64,
    solution: Solution,
) -> MethodComparison {
    let h = basis.harmonics();
    let error = model_relative_error(&scene.model, solution.harmonics(), &td.harmonics, h);
    let samples = td.samples.first().map_or(0, |s| s.len());
    // The exact method by its closed form in time, with the ringing above H.
    let series = (method == "piecewise_exact")
        .then(|| {
            PiecewiseExact::new()
                .solve_exact(&scene.model, basis)
                .and_then(|e| e.series_harmonics(samples))
                .ok()
        })
        .flatten();
    let worst_quantity = (basis.subharmonic() == 1)
        .then(|| {
            let q = series.as_deref().unwrap_or(solution.harmonics());
            crate::compare::quantity_errors(&scene.model, basis, q, &td.harmonics, samples).ok()
        })
        .flatten()
        .and_then(|q| crate::compare::quantities::worst(&q, |_| true));
    MethodComparison {
        method,
        seconds,
        solution,
        error,
        worst_quantity,
    }
}

impl CompareAnalysis {
    /// 0 where some method converged, else 1 (the table and the reference stand).
    pub fn exit_code(&self) -> u8 {
        u8::from(!self.methods.iter().any(|m| m.solution.is_converged()))
    }

    /// The name of method `i`'s worst quantity.
    pub fn quantity_name(&self, i: usize) -> Option<&str> {
        self.quantity_names.get(i).and_then(|n| n.as_deref())
    }

    /// The JSON record (what `Serialize` writes): `hbal compare --json`.
    pub fn to_json(&self) -> Value {
        let td = &self.time_domain;
        let rows: Vec<Value> = self
            .methods
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let sol = &m.solution;
                json!({
                    "method": m.method,
                    "converged": sol.is_converged(),
                    "termination": sol.termination.to_string(),
                    "iterations": sol.stats.iterations,
                    "residual": sol.residual(),
                    "solve_seconds": m.seconds,
                    "error_vs_time_domain": m.error,
                    "worst_quantity_vs_time_domain": m.worst_quantity.map(|q| json!({
                        "name": self.quantity_name(i),
                        "quantity": q.quantity,
                        "error": q.error,
                        "range": q.range,
                    })),
                })
            })
            .collect();
        json!({
            "schema_version": super::SCHEMA_VERSION,
            "scene": self.file,
            "harmonics": self.basis.harmonics(),
            "samples": self.basis.samples(),
            "time_domain": {
                "started_on_hb_orbit": self.started_on_hb_orbit,
                "converged": td.converged,
                "stop": format!("{:?}", td.stop),
                "periods": td.periods,
                "steps": td.steps,
                "seconds": td.wall_time.as_secs_f64(),
            },
            "methods": rows,
        })
    }
}

impl serde::Serialize for CompareAnalysis {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.to_json().serialize(s)
    }
}
