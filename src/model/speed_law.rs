//! How a load harmonic follows the speed: a power of the speed, or a table over speed.
//!
//! A load harmonic whose amplitude depends on the reference speed Ω (the fundamental's shaft
//! speed) is its base phasor `c + i s` times a complex factor `T(Ω)`:
//!
//! - a power law `T(Ω) = (Ω / Ω_ref)^n`: a propeller torque (n = 2), an unbalance or the
//!   inertia torque of reciprocating masses (n = 2); the base phasor is the load at `Ω_ref`;
//! - a table `T(Ω) = A(Ω) e^{-iψ(Ω)}` with the amplitude `A` and the phase `ψ` linear
//!   between the table's speeds (an engine's order torques from a torque map over speed); the
//!   load is then `A cos(kΩt + ψ)`, the engine table's phase convention.
//!
//! Speeds are written in rpm of the reference shaft; a model whose fundamental is the order
//! `f` of it (`Ω = f Ω_ref`, [`SpeedLaw::fundamental_order`]) evaluates the law at `Ω / f`.
//! A table is never extrapolated: a speed outside it is an error ([`SpeedLaw::covers`]).
//!
//! ```
//! use hbal::model::{SpeedLaw, Speeds};
//! let propeller = SpeedLaw::power(2.0, 1500.0);
//! let omega = 3000.0 * std::f64::consts::TAU / 60.0;
//! assert!((propeller.factor(omega).re - 4.0).abs() < 1e-12);
//! let map = SpeedLaw {
//!     exponent: None,
//!     rpm: Speeds::Table(vec![1000.0, 2000.0]),
//!     amplitude: vec![100.0, 300.0],
//!     phase: vec![],
//!     fundamental_order: 1.0,
//! };
//! let mid = map.factor(1500.0 * std::f64::consts::TAU / 60.0);
//! assert!((mid.re - 200.0).abs() < 1e-9 && mid.im.abs() < 1e-12);
//! assert!(map.validate("load").is_ok());
//! ```

use crate::error::{Error, Result};
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// rad/s per rpm.
const RAD_S_PER_RPM: f64 = std::f64::consts::TAU / 60.0;

/// A speed law's speeds: one reference (a power law) or a table's speeds, rpm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Speeds {
    /// The reference speed of a power law.
    Reference(f64),
    /// A table's speeds, strictly increasing.
    Table(Vec<f64>),
}

/// The factor `T(Ω)` a load harmonic's base phasor is multiplied by (module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpeedLaw {
    /// The exponent n of a power law `(Ω / Ω_ref)^n`; `None` for a table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exponent: Option<f64>,
    /// The reference speed (power law) or the table's speeds, rpm.
    pub rpm: Speeds,
    /// A table's amplitudes, one per speed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub amplitude: Vec<f64>,
    /// A table's phases ψ (rad), one per speed; empty for zero phase.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub phase: Vec<f64>,
    /// The order `f` of the model's fundamental relative to the reference shaft whose rpm
    /// the law is written in (`Ω = f Ω_ref`; 1 unless the scene chose another fundamental).
    #[serde(skip, default = "one")]
    pub fundamental_order: f64,
}

fn one() -> f64 {
    1.0
}

impl SpeedLaw {
    /// The power law `(Ω / Ω_ref)^exponent` with `Ω_ref` in rpm.
    pub fn power(exponent: f64, reference_rpm: f64) -> Self {
        Self {
            exponent: Some(exponent),
            rpm: Speeds::Reference(reference_rpm),
            amplitude: Vec::new(),
            phase: Vec::new(),
            fundamental_order: 1.0,
        }
    }

    /// The law for a model whose fundamental is the order `f` of the reference shaft.
    pub fn on_fundamental_order(mut self, f: f64) -> Self {
        self.fundamental_order = f;
        self
    }

    /// rad/s of the fundamental per rpm of the reference shaft.
    fn per_rpm(&self) -> f64 {
        RAD_S_PER_RPM * self.fundamental_order
    }

    /// The speeds (rpm of the reference shaft) the law is defined on: a table's first and
    /// last speed; the power law's `(0, ∞)`.
    pub fn range_rpm(&self) -> (f64, f64) {
        let (a, b) = self.range();
        (a / self.per_rpm(), b / self.per_rpm())
    }

    /// `true` for a table (amplitude and phase given over speed).
    pub fn is_table(&self) -> bool {
        self.exponent.is_none()
    }

    /// Checks the law: a power law has a finite exponent and a reference speed > 0; a table
    /// has at least two strictly increasing speeds >= 0 and finite amplitudes (and phases),
    /// one per speed. `context` names the load in the error.
    pub fn validate(&self, context: &str) -> Result<()> {
        let bad = |field: &str, why: String| Error::InvalidElement {
            context: context.into(),
            reason: format!("`{field}` {why}"),
        };
        match (&self.exponent, &self.rpm) {
            (Some(n), Speeds::Reference(r)) => {
                if !n.is_finite() || n.abs() > 16.0 {
                    return Err(bad(
                        "exponent",
                        format!("must be finite and within ±16, got {n}"),
                    ));
                }
                if !(r.is_finite() && *r > 0.0) {
                    return Err(bad("rpm", format!("must be finite and > 0, got {r}")));
                }
                if !self.amplitude.is_empty() || !self.phase.is_empty() {
                    return Err(bad("amplitude", "belongs to a table over speed (`rpm` a list, no `exponent`); a power law scales the load's own amplitude".into()));
                }
            }
            (Some(_), Speeds::Table(_)) => {
                return Err(bad("exponent", "needs one reference speed `rpm = <number>`; a table over speed (`rpm` a list) has no exponent".into()));
            }
            (None, Speeds::Reference(_)) => {
                return Err(bad("rpm", "is one speed: give `exponent` for a power law, or lists `rpm`, `amplitude` (and `phase`) for a table".into()));
            }
            (None, Speeds::Table(rpm)) => self.validate_table(rpm, &bad)?,
        }
        Ok(())
    }

    fn validate_table(&self, rpm: &[f64], bad: &dyn Fn(&str, String) -> Error) -> Result<()> {
        if rpm.len() < 2 {
            return Err(bad(
                "rpm",
                format!("needs at least two speeds, got {}", rpm.len()),
            ));
        }
        for (i, w) in rpm.windows(2).enumerate() {
            if !(w[0].is_finite() && w[1].is_finite() && w[0] >= 0.0 && w[1] > w[0]) {
                return Err(bad(
                    "rpm",
                    format!(
                        "must be finite, >= 0 and strictly increasing: rpm[{i}] = {}, rpm[{}] = {}",
                        w[0],
                        i + 1,
                        w[1]
                    ),
                ));
            }
        }
        for (name, values, optional) in [
            ("amplitude", &self.amplitude, false),
            ("phase", &self.phase, true),
        ] {
            if values.len() != rpm.len() && !(optional && values.is_empty()) {
                return Err(bad(
                    name,
                    format!(
                        "must have one value per speed ({}), got {}",
                        rpm.len(),
                        values.len()
                    ),
                ));
            }
            if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(bad(name, format!("must be finite, got {name}[{i}] = {v}")));
            }
        }
        Ok(())
    }

    /// The fundamental's speeds Ω (rad/s) the law is defined on: a table's first and last
    /// speed; the power law's `(0, ∞)`.
    pub fn range(&self) -> (f64, f64) {
        match &self.rpm {
            Speeds::Table(rpm) if !rpm.is_empty() => {
                (rpm[0] * self.per_rpm(), rpm[rpm.len() - 1] * self.per_rpm())
            }
            _ => (0.0, f64::INFINITY),
        }
    }

    /// `true` if the law is defined at every speed from `lo` to `hi` (rad/s), with a relative
    /// slack of 1e-12 at a table's ends.
    pub fn covers(&self, lo: f64, hi: f64) -> bool {
        let (a, b) = self.range();
        let slack = 1e-12 * b.abs().min(1e300);
        lo >= a - slack && hi <= b + slack && if self.is_table() { true } else { lo > 0.0 }
    }

    /// `T(Ω)` at the fundamental's Ω (rad/s); a table is held at its end values outside its speeds (an analysis
    /// checks [`covers`](Self::covers) first).
    pub fn factor(&self, omega: f64) -> Complex64 {
        self.value_and_slope(omega).0
    }

    /// `dT/dΩ` at Ω (rad/s): a table's slope on the segment holding Ω (its right one at a
    /// table speed), 0 outside the table.
    pub fn derivative(&self, omega: f64) -> Complex64 {
        self.value_and_slope(omega).1
    }

    fn value_and_slope(&self, omega: f64) -> (Complex64, Complex64) {
        match (&self.exponent, &self.rpm) {
            (Some(n), Speeds::Reference(r)) => {
                let reference = r * self.per_rpm();
                let t = (omega / reference).powf(*n);
                let slope = if omega > 0.0 { n * t / omega } else { 0.0 };
                (Complex64::new(t, 0.0), Complex64::new(slope, 0.0))
            }
            (_, Speeds::Table(rpm)) if rpm.len() >= 2 => self.table_at(rpm, omega / self.per_rpm()),
            _ => (Complex64::new(1.0, 0.0), Complex64::default()),
        }
    }

    /// `A e^{-iψ}` and its Ω-derivative at `n` rpm, linear in A and ψ between speeds.
    fn table_at(&self, rpm: &[f64], n: f64) -> (Complex64, Complex64) {
        let last = rpm.len() - 1;
        let phase = |i: usize| self.phase.get(i).copied().unwrap_or(0.0);
        let amplitude = |i: usize| self.amplitude.get(i).copied().unwrap_or(0.0);
        let polar = |a: f64, psi: f64| Complex64::from_polar(1.0, -psi) * a;
        if n <= rpm[0] || n >= rpm[last] {
            let i = if n <= rpm[0] { 0 } else { last };
            return (polar(amplitude(i), phase(i)), Complex64::default());
        }
        // The segment [rpm[i], rpm[i+1]) holding n.
        let i = rpm
            .partition_point(|&r| r <= n)
            .saturating_sub(1)
            .min(last - 1);
        let width = rpm[i + 1] - rpm[i];
        let s = (n - rpm[i]) / width;
        let a = amplitude(i) + s * (amplitude(i + 1) - amplitude(i));
        let psi = phase(i) + s * (phase(i + 1) - phase(i));
        // d/dn of a e^{-iψ} = (a' - i a ψ') e^{-iψ} per rpm; per rad/s of Ω divided by per_rpm.
        let da = (amplitude(i + 1) - amplitude(i)) / width;
        let dpsi = (phase(i + 1) - phase(i)) / width;
        let unit = Complex64::from_polar(1.0, -psi);
        let slope = Complex64::new(da, -a * dpsi) * unit / self.per_rpm();
        (unit * a, slope)
    }
}
