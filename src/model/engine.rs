//! Engine excitation: the gas and mass torque of a piston engine given per order, per cylinder,
//! with a firing order, turned into harmonic loads.
//!
//! Each cylinder `c` of an engine turning at the crank angle `φ = Ω_ref t` (the reference
//! shaft of the scene's `rpm`) applies the same torque shape, shifted by its firing angle
//! `φ_c`:
//!
//! `T_c(φ) = T̄ + Σ_o A_o cos(o (φ - φ_c) + ψ_o)`  (N m),
//!
//! with the mean torque `T̄`, and for each engine order `o` (half orders for a four-stroke
//! engine, whose cycle spans two revolutions) the amplitude `A_o` and phase `ψ_o`. Cylinder
//! `firing_order[j]` fires at `φ_c = j · 4π / n` for a four-stroke engine of `n` cylinders
//! (`2π / n` for a two-stroke), unless `firing_angles` gives every cylinder's angle.
//!
//! Under a fundamental of order `f` (`Ω = f Ω_ref`) the order `o` is the harmonic `k = o / f`,
//! so every order must be a whole multiple of `f`; [`EngineExcitation::fundamental_order`]
//! gives the largest `f <= 1` that makes them all harmonics (0.5 with half orders). With
//! `θ = Ω t = f φ`, `A cos(o(φ - φ_c) + ψ) = A cos α cos kθ + A sin α sin kθ` with
//! `α = o φ_c - ψ`, which is the load's `(cos, sin)` pair.

use super::SpeedLaw;
use crate::error::{check_finite, check_non_negative, Error, Result};
use std::f64::consts::TAU;

/// One engine order of a cylinder's torque: `A cos(o (φ - φ_c) + ψ)`, with `A`, `ψ`
/// constant, scaled by a power of the speed, or taken from a table over speed
/// ([`SpeedLaw`]: then `amplitude` and `phase` are not given, NaN and 0 here).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineOrder {
    /// The order `o` (> 0), in multiples of the crank speed: 0.5, 1, 1.5, ...
    pub order: f64,
    /// Amplitude `A` per cylinder, N m (>= 0; at the reference speed of a power law); NaN
    /// where a table gives it.
    #[serde(default = "not_given", skip_serializing_if = "f64_is_nan")]
    pub amplitude: f64,
    /// Phase `ψ`, rad (default 0).
    #[serde(default)]
    pub phase: f64,
    /// How `A` and `ψ` follow the speed, if they do.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<SpeedLaw>,
}

impl EngineOrder {
    /// The order `o` with the constant amplitude `A` and phase `ψ`.
    pub fn new(order: f64, amplitude: f64, phase: f64) -> Self {
        Self {
            order,
            amplitude,
            phase,
            speed: None,
        }
    }
}

fn not_given() -> f64 {
    f64::NAN
}

fn f64_is_nan(a: &f64) -> bool {
    a.is_nan()
}

/// Where the cylinders' torques act: all on one DOF, or one DOF per cylinder (crank throws).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(untagged)]
pub enum Cylinders {
    /// Number of cylinders, all acting on [`EngineExcitation::dof`].
    Count(usize),
    /// One DOF per cylinder, cylinder 1 first.
    Dofs(Vec<String>),
}

/// A piston engine's torque excitation (module documentation for the formula).
///
/// ```
/// use hbal::model::{Cylinders, EngineExcitation, EngineOrder};
/// // A four-cylinder four-stroke engine, firing order 1-3-4-2, on one crank DOF.
/// let engine = EngineExcitation {
///     dof: Some("crank".into()),
///     cylinders: Cylinders::Count(4),
///     strokes: 4,
///     firing_order: Some(vec![1, 3, 4, 2]),
///     firing_angles: None,
///     mean_torque: 25.0,
///     orders: vec![
///         EngineOrder::new(0.5, 30.0, 0.0),
///         EngineOrder::new(2.0, 60.0, 0.0),
///     ],
/// };
/// assert_eq!(engine.fundamental_order(), Some(0.5));
/// let loads = engine.loads(0.5).unwrap();
/// // The mean: 4 x 25 N m; order 2 (harmonic 4): four cylinders in phase, 4 x 60 N m;
/// // order 0.5 cancels over the firing order.
/// let at = |k| loads.iter().filter(|l| l.1 == k).map(|l| (l.2, l.3)).fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
/// assert!((at(0).0 - 100.0).abs() < 1e-12);
/// assert!((at(4).0 - 240.0).abs() < 1e-12 && at(4).1.abs() < 1e-12);
/// assert!(at(1).0.abs() < 1e-12 && at(1).1.abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineExcitation {
    /// The DOF all cylinders act on, when `cylinders` is a count.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dof: Option<String>,
    /// A cylinder count (with `dof`) or one DOF per cylinder.
    pub cylinders: Cylinders,
    /// 4 (default) or 2.
    #[serde(default = "four")]
    pub strokes: u32,
    /// Cylinder numbers (1-based) in firing sequence; default 1, 2, ..., n.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub firing_order: Option<Vec<usize>>,
    /// Firing angle of every cylinder (cylinder 1 first), rad, instead of an even spacing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub firing_angles: Option<Vec<f64>>,
    /// Mean torque per cylinder, N m (default 0).
    #[serde(default)]
    pub mean_torque: f64,
    /// The torque's orders, per cylinder.
    #[serde(default)]
    pub orders: Vec<EngineOrder>,
}

/// One load of an engine: `(DOF, harmonic k, cos, sin, speed law)`.
pub type EngineLoad = (String, usize, f64, f64, Option<SpeedLaw>);

fn four() -> u32 {
    4
}

/// Largest denominator tried when turning orders into fractions.
const MAX_DENOMINATOR: u64 = 1000;

impl EngineExcitation {
    /// Largest number of cylinders (the largest engines have 24).
    pub const MAX_CYLINDERS: usize = 64;

    /// The number of cylinders.
    pub fn count(&self) -> usize {
        match &self.cylinders {
            Cylinders::Count(n) => *n,
            Cylinders::Dofs(d) => d.len(),
        }
    }

    /// The DOF each cylinder acts on, cylinder 1 first.
    pub fn cylinder_dofs(&self) -> Vec<String> {
        match &self.cylinders {
            Cylinders::Count(n) => vec![self.dof.clone().unwrap_or_default(); *n],
            Cylinders::Dofs(d) => d.clone(),
        }
    }

    /// The firing angle `φ_c` of every cylinder (cylinder 1 first), rad.
    pub fn firing_angles(&self) -> Vec<f64> {
        let n = self.count();
        if let Some(a) = &self.firing_angles {
            return a.clone();
        }
        let interval = TAU * self.strokes as f64 / 2.0 / n as f64;
        let order: Vec<usize> = self
            .firing_order
            .clone()
            .unwrap_or_else(|| (1..=n).collect());
        let mut angles = vec![0.0; n];
        for (j, &c) in order.iter().enumerate() {
            if (1..=n).contains(&c) {
                angles[c - 1] = j as f64 * interval;
            }
        }
        angles
    }

    /// The largest fundamental order `f <= 1` of which every engine order is a whole
    /// multiple (1 for whole orders, 0.5 with half orders), or `None` if the orders have no
    /// common divisor with a denominator up to 1000.
    pub fn fundamental_order(&self) -> Option<f64> {
        common_divisor(self.orders.iter().map(|o| o.order).chain([1.0]))
    }

    /// Checks every field; `context` names the excitation in messages.
    pub fn validate(&self, context: &str) -> Result<()> {
        let n = self.count();
        let bad = |name: &str, requirement: String| Error::InvalidElement {
            context: context.into(),
            reason: format!("`{name}` {requirement}"),
        };
        if n == 0 {
            return Err(bad("cylinders", "must name at least one cylinder".into()));
        }
        if n > Self::MAX_CYLINDERS {
            return Err(bad(
                "cylinders",
                format!("must be at most {}, got {n}", Self::MAX_CYLINDERS),
            ));
        }
        match (&self.cylinders, &self.dof) {
            (Cylinders::Count(_), None) => {
                return Err(bad(
                    "dof",
                    "is missing: a cylinder count needs the DOF they act on".into(),
                ))
            }
            (Cylinders::Dofs(_), Some(_)) => {
                return Err(bad(
                    "dof",
                    "must not be given with one DOF per cylinder in `cylinders`".into(),
                ))
            }
            _ => {}
        }
        if self.strokes != 2 && self.strokes != 4 {
            return Err(Error::invalid(
                context,
                "strokes",
                self.strokes as f64,
                "2 or 4",
            ));
        }
        if let Some(order) = &self.firing_order {
            let mut sorted = order.clone();
            sorted.sort_unstable();
            if sorted != (1..=n).collect::<Vec<_>>() {
                return Err(bad(
                    "firing_order",
                    format!("must list each of the {n} cylinders 1..={n} once, got {order:?}"),
                ));
            }
        }
        if let Some(a) = &self.firing_angles {
            if self.firing_order.is_some() {
                return Err(bad(
                    "firing_angles",
                    "and `firing_order` exclude each other: give one".into(),
                ));
            }
            if a.len() != n {
                return Err(bad(
                    "firing_angles",
                    format!("must have one angle per cylinder ({n}), got {}", a.len()),
                ));
            }
            for (i, x) in a.iter().enumerate() {
                check_finite(context, &format!("firing_angles[{i}]"), *x)?;
            }
        }
        check_finite(context, "mean_torque", self.mean_torque)?;
        for (i, o) in self.orders.iter().enumerate() {
            if !(o.order.is_finite() && o.order > 0.0 && o.order <= 1e6) {
                return Err(Error::invalid(
                    context,
                    format!("orders[{i}].order"),
                    o.order,
                    "finite, > 0 and at most 1e6 (the mean is `mean_torque`)",
                ));
            }
            match &o.speed {
                Some(law) if law.is_table() => {
                    if !o.amplitude.is_nan() || o.phase != 0.0 {
                        return Err(bad(
                            &format!("orders[{i}].amplitude"),
                            "and `phase` are given by the table `speed`: leave them out".into(),
                        ));
                    }
                }
                _ if o.amplitude.is_nan() => {
                    return Err(bad(
                        &format!("orders[{i}].amplitude"),
                        "is missing (N m per cylinder; or give a table over speed in `speed`)"
                            .into(),
                    ));
                }
                _ => {
                    check_non_negative(context, &format!("orders[{i}].amplitude"), o.amplitude)?;
                    check_finite(context, &format!("orders[{i}].phase"), o.phase)?;
                }
            }
            if let Some(law) = &o.speed {
                law.validate(&format!("{context} orders[{i}].speed"))?;
            }
        }
        if self.fundamental_order().is_none() {
            return Err(bad(
                "orders",
                "have no common divisor with a denominator up to 1000: no fundamental makes \
                 them all harmonics"
                    .into(),
            ));
        }
        Ok(())
    }

    /// The loads `(DOF, harmonic k, cos, sin, speed law)` under a fundamental of order
    /// `fundamental` (module documentation; with a table over speed, `(cos, sin)` is the
    /// cylinder's unit phasor `e^{i o φ_c}`); an order that is not a whole multiple of it is
    /// an error that names the order and the fundamental that would hold it.
    pub fn loads(&self, fundamental: f64) -> Result<Vec<EngineLoad>> {
        let dofs = self.cylinder_dofs();
        let angles = self.firing_angles();
        let mut out = Vec::with_capacity(dofs.len() * (self.orders.len() + 1));
        for (i, o) in self.orders.iter().enumerate() {
            let k = o.order / fundamental;
            let kr = k.round();
            if (k - kr).abs() > 1e-9 * k.max(1.0) || kr < 1.0 {
                return Err(Error::invalid(
                    "engine",
                    format!("orders[{i}].order"),
                    o.order,
                    format!(
                        "a whole multiple of the fundamental's order {fundamental} (set \
                         `fundamental.order = {}` or leave it out)",
                        self.fundamental_order().unwrap_or(fundamental)
                    ),
                ));
            }
        }
        for (dof, &phi) in dofs.iter().zip(&angles) {
            if self.mean_torque != 0.0 {
                out.push((dof.clone(), 0, self.mean_torque, 0.0, None));
            }
            for o in &self.orders {
                let k = (o.order / fundamental).round() as usize;
                let alpha = o.order * phi - o.phase;
                let a = if o.amplitude.is_nan() {
                    1.0
                } else {
                    o.amplitude
                };
                out.push((
                    dof.clone(),
                    k,
                    a * alpha.cos(),
                    a * alpha.sin(),
                    o.speed.clone().map(|l| l.on_fundamental_order(fundamental)),
                ));
            }
        }
        Ok(out)
    }
}

/// The largest `f` of which every value is a whole multiple, as a fraction `p/q` with
/// `q <= MAX_DENOMINATOR`; `None` if some value is not such a fraction (to 1e-9).
pub(crate) fn common_divisor(values: impl Iterator<Item = f64>) -> Option<f64> {
    // Orders up to 1e6 (beyond any engine or mesh order) keep the products below in u128.
    const MAX_VALUE: f64 = 1e6;
    let mut fractions = Vec::new();
    for v in values {
        if !(v.is_finite() && v > 0.0 && v <= MAX_VALUE) {
            return None;
        }
        let q = (1..=MAX_DENOMINATOR).find(|&q| {
            let p = v * q as f64;
            (p - p.round()).abs() <= 1e-9 * p.abs().max(1.0)
        })?;
        fractions.push(((v * q as f64).round() as u64, q));
    }
    // gcd of p_i/q_i = gcd(p_i L/q_i) / L with L = lcm(q_i) (at most 1e9: else no fundamental
    // a harmonic basis could use).
    let mut l = 1u64;
    for &(_, q) in &fractions {
        l = l / gcd(l, q) * q;
        if l > 1_000_000_000 {
            return None;
        }
    }
    let g = fractions.iter().fold(0u64, |g, &(p, q)| {
        // p <= 1e9 and L/q <= 1e9: the product fits in u64.
        gcd(g, p * (l / q))
    });
    (g > 0).then(|| g as f64 / l as f64)
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}
