//! Natural frequencies and mode shapes of a scene linearised about its periodic solution
//! ([`modes()`], `hbal modes`): with the one- and two-tooth bounds of time-varying meshes, the
//! excitation orders and the critical speeds where an order line `f = o · n` meets a natural
//! frequency in the speed range.

use crate::report::{natural_frequencies, NaturalFrequencies};
use crate::scene::Scene;
use crate::{Error, Formulation, HarmonicBalance, HarmonicBasis, Result, Termination};
use serde_json::{json, Value};
use std::f64::consts::TAU;

/// What `hbal modes` computes besides the scene.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ModesSettings {
    /// The lowest speed of the critical-speed range (the scene's unit; default 0).
    pub from: Option<f64>,
    /// The highest speed (default twice the scene's speed).
    pub to: Option<f64>,
    /// Modes up to this frequency (Hz; default every mode up to 300 DOFs, else 5000 Hz).
    pub max_hz: Option<f64>,
    /// The formulation of the operating point's harmonic balance.
    pub formulation: Formulation,
}

/// Where an excitation order meets a natural frequency.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CriticalSpeed {
    /// The order of the reference speed.
    pub order: f64,
    /// The mode, from 1.
    pub mode: usize,
    /// The speed (the scene's unit).
    pub speed: f64,
}

/// Everything `hbal modes` reports.
#[derive(Debug, Clone)]
pub struct ModesAnalysis {
    /// The scene's file.
    pub file: String,
    /// The scene's speed unit.
    pub unit: String,
    /// The scene's speed, where the model is linearised; `None` for a scene without an
    /// operating point (no `fundamental`, `harmonics`).
    pub operating_speed: Option<f64>,
    /// The critical-speed range (the scene's unit).
    pub range: (f64, f64),
    /// The frequency limit (Hz; infinite for every mode).
    pub max_hz: f64,
    /// How the operating point's solve ended.
    pub termination: Termination,
    /// `true` where every law is linear in the state: the frequencies do not depend on an
    /// operating point, and none was solved for.
    pub linear: bool,
    /// The natural frequencies; `None` where the operating point did not converge.
    pub natural: Option<NaturalFrequencies>,
    /// The excitation orders of the reference speed.
    pub orders: Vec<f64>,
    /// The critical speeds in the range, by speed (as a run-up meets them).
    pub critical: Vec<CriticalSpeed>,
    /// The DOF names (the rows of the shapes).
    pub dofs: Vec<String>,
    /// rad/s of the reference shaft per unit of speed.
    pub per_unit: f64,
}

/// The excitation orders (multiples of the reference speed) of `scene` and their harmonic
/// index on `basis`, where they are harmonics of it: the loads' and the meshes' orders.
pub fn excitation_orders(scene: &Scene, basis: &HarmonicBasis) -> Vec<(f64, usize)> {
    let nu = basis.subharmonic();
    let f = scene.fundamental_order / nu as f64;
    let loads = scene
        .model
        .loads()
        .iter()
        .filter(|l| l.order > 0)
        .map(|l| l.order * nu);
    let elements = scene.model.elements().iter();
    let meshes = elements
        .filter_map(|e| e.law().time_order())
        .map(|z| z * nu);
    let mut ks: Vec<usize> = loads
        .chain(meshes)
        .filter(|&k| k <= basis.harmonics())
        .collect();
    ks.sort_unstable();
    ks.dedup();
    ks.into_iter().map(|k| (k as f64 * f, k)).collect()
}

/// The excitation orders of a scene on several base frequencies: each load's and each law's
/// time order times its base's order of the speed.
fn torus_orders(scene: &Scene, plan: &crate::scene::TorusPlan) -> Result<Vec<f64>> {
    let tm = plan.bind(&scene.model)?;
    let ratios = plan.bases.ratios();
    let loads = scene
        .model
        .loads()
        .iter()
        .enumerate()
        .filter(|(_, l)| l.order > 0)
        .map(|(i, l)| l.order as f64 * ratios[tm.load_base(i)]);
    let elements = scene.model.elements().iter().enumerate();
    let meshes = elements.filter_map(|(e, el)| {
        el.law()
            .time_order()
            .map(|z| z as f64 * ratios[tm.element_base(e)])
    });
    let mut orders: Vec<f64> = loads.chain(meshes).collect();
    orders.sort_by(f64::total_cmp);
    orders.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    Ok(orders)
}

/// The modes of `scene` about its periodic solution (module documentation).
///
/// # Errors
/// Bad input before any work: speeds out of range or `to <= from`, a non-positive
/// `max_hz`, a model the harmonic balance refuses. An operating point that does not
/// converge is a result without modes, marked ([`ModesAnalysis::exit_code`]).
pub fn modes(scene: &Scene, settings: &ModesSettings) -> Result<ModesAnalysis> {
    let speed = scene.basis.omega() / scene.omega_per_speed;
    let (from, to) = (
        settings.from.unwrap_or(0.0),
        settings.to.unwrap_or(2.0 * speed),
    );
    super::check_speed(scene, "--from", from, true)?;
    super::check_speed(scene, "--to", to, false)?;
    let bad = |option: &str, reason: String| Error::InvalidOptions {
        option: option.into(),
        reason,
    };
    if to <= from {
        let reason = format!(
            "{from} --to {to}: need 0 <= from < to (in {})",
            scene.speed_unit
        );
        return Err(bad("--from", reason));
    }
    let max_hz = match settings.max_hz {
        Some(f) if !(f.is_finite() && f > 0.0 && f <= crate::error::MAX_MAGNITUDE) => {
            let got = crate::report::significant(f, 6);
            return Err(bad(
                "--max-hz",
                format!("must be finite, > 0 and at most 1e100, got {got}"),
            ));
        }
        Some(f) => f,
        None if scene.model.n_dofs() <= 300 => f64::INFINITY,
        None => 5000.0,
    };
    let (termination, natural, linear) = operating_point(scene, settings, max_hz)?;
    let orders: Vec<f64> = match &scene.torus {
        Some(plan) => torus_orders(scene, plan)?,
        None => excitation_orders(scene, &scene.basis)
            .into_iter()
            .map(|(o, _)| o)
            .collect(),
    };
    let per_unit = scene.omega_per_speed / scene.fundamental_order;
    // Without an operating point (and `--to`), up to a quarter above the highest critical speed.
    let to = match (&natural, settings.to, scene.operating_point) {
        (Some(nf), None, false) => critical_speeds(nf, &orders, per_unit, (from, f64::MAX))
            .iter()
            .map(|c| 1.25 * c.speed)
            .fold(None, |m: Option<f64>, s| Some(m.map_or(s, |m| m.max(s))))
            .unwrap_or(to),
        _ => to,
    };
    let critical = natural
        .as_ref()
        .map(|nf| critical_speeds(nf, &orders, per_unit, (from, to)))
        .unwrap_or_default();
    Ok(ModesAnalysis {
        file: scene.file.clone(),
        unit: scene.speed_unit.to_string(),
        operating_speed: scene.operating_point.then_some(speed),
        range: (from, to),
        max_hz,
        termination,
        natural,
        linear,
        orders,
        critical,
        dofs: scene.model.dof_names().to_vec(),
        per_unit,
    })
}

/// How the operating point's solve ended, the natural frequencies linearised on it, and
/// whether the model is linear in the state: then no solve (a free line held only by
/// damping, or one whose statics the loads leave undetermined, still has its modes).
fn operating_point(
    scene: &Scene,
    settings: &ModesSettings,
    max_hz: f64,
) -> Result<(Termination, Option<NaturalFrequencies>, bool)> {
    let model = &scene.model;
    if model
        .elements()
        .iter()
        .all(|e| e.law().is_linear_in_state())
    {
        let rest = vec![0.0; model.n_dofs()];
        let natural = crate::report::natural_frequencies_at(model, &rest, max_hz)?;
        return Ok((Termination::Converged, Some(natural), true));
    }
    // A nonlinear model's modes depend on its orbit, at the scene's operating point.
    scene.require_operating_point("modes of a model nonlinear in the state")?;
    let hb = HarmonicBalance::with_formulation(model, scene.basis, settings.formulation)?;
    let sol = scene.method.solve(&hb, None, &mut hb.workspace())?;
    let natural = match sol.is_converged() {
        true => Some(natural_frequencies(model, &sol, max_hz)?),
        false => None,
    };
    Ok((sol.termination, natural, false))
}

/// Where the order lines meet the elastic modes' mean frequencies within `range`.
fn critical_speeds(
    nf: &NaturalFrequencies,
    orders: &[f64],
    per_unit: f64,
    (from, to): (f64, f64),
) -> Vec<CriticalSpeed> {
    let elastic = || nf.mean.iter().enumerate().filter(|(_, f)| **f > 0.0);
    let mut critical = orders
        .iter()
        .flat_map(|&order| {
            elastic().map(move |(i, &f)| CriticalSpeed {
                order,
                mode: i + 1,
                speed: TAU * f / (order * per_unit),
            })
        })
        .filter(|c| c.speed >= from && c.speed <= to)
        .collect::<Vec<_>>();
    // By speed, as a run-up meets them (ties by order, then mode).
    critical.sort_by(|a, b| a.speed.total_cmp(&b.speed));
    critical
}

impl ModesAnalysis {
    /// 0 with modes, 1 where the operating point did not converge (the document marked).
    pub fn exit_code(&self) -> u8 {
        u8::from(self.natural.is_none())
    }

    /// The JSON record: `hbal modes --json`.
    pub fn to_json(&self) -> Value {
        let Some(nf) = &self.natural else {
            return json!({
                "schema_version": super::SCHEMA_VERSION,
                "scene": self.file,
                "unit": self.unit,
                "operating_speed": self.operating_speed,
                "converged": false,
                "termination": self.termination.to_string(),
                "error": "the operating point did not converge: no linearisation",
                "modes": [],
                "critical_speeds": [],
            });
        };
        let modes: Vec<Value> = nf
            .mean
            .iter()
            .enumerate()
            .map(|(i, f)| {
                json!({
                    "mean_hz": f,
                    "lower_hz": nf.lower.get(i),
                    "upper_hz": nf.upper.get(i),
                    "shape": nf.shapes.column(i).iter().collect::<Vec<_>>(),
                })
            })
            .collect();
        json!({
            "schema_version": super::SCHEMA_VERSION,
            "scene": self.file,
            "unit": self.unit,
            "operating_speed": self.operating_speed,
            "converged": true,
            "linear": self.linear,
            "rigid_modes": nf.rigid,
            "modes": modes,
            "dofs": self.dofs,
            "orders": self.orders,
            "critical_speeds": self.critical,
        })
    }
}

impl serde::Serialize for ModesAnalysis {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        self.to_json().serialize(s)
    }
}
