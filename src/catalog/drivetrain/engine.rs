//! The engine side of a [`Drivetrain`](super::Drivetrain): the 4-cylinder engine with its
//! gas torque, and the clutch damper. Units: SI (kg m², N m/rad, N m s/rad, rad).

use crate::error::{check_non_negative, check_positive, Error, Result};
use std::f64::consts::PI;

/// A 4-cylinder, 4-stroke in-line engine: torsional vibration damper, crank nose, four crank
/// throws, flywheel; the gas torque of each cylinder.
///
/// Default: a 2-litre class engine (stroke 90 mm); throws include the rotating and half the
/// oscillating con-rod and piston mass. The crank's first mode against the flywheel is at
/// 840 Hz (without the damper); the damper ring is tuned a little below it (`√(k/J)` =
/// 4.7e3 rad/s, 750 Hz) with a rubber damping ratio `c / (2√(kJ))` ≈ 0.15.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Engine {
    /// Inertia ring of the torsional vibration damper (kg m²).
    pub damper_ring: f64,
    /// Rubber stiffness between ring and pulley (N m/rad).
    pub damper_stiffness: f64,
    /// Rubber damping between ring and pulley (N m s/rad).
    pub damper_damping: f64,
    /// Pulley hub and crank nose (kg m²).
    pub pulley: f64,
    /// One crank throw (kg m²).
    pub throw: f64,
    /// Crank stiffness pulley → throw 1 (N m/rad).
    pub nose_stiffness: f64,
    /// Crank stiffness between neighbouring throws (N m/rad).
    pub throw_stiffness: f64,
    /// Crank stiffness throw 4 → flywheel (N m/rad).
    pub flange_stiffness: f64,
    /// Flywheel with clutch cover and pressure plate (kg m²).
    pub flywheel: f64,
    /// Firing order (cylinder numbers 1..=4 from the pulley end), one firing every 180°.
    pub firing_order: [usize; 4],
    /// Amplitudes of one cylinder's torque harmonics relative to its mean torque, for the
    /// crank orders 0.5, 1, 1.5, ... (entry j is order (j+1)/2, the model's harmonic j+1).
    pub gas_orders: Vec<f64>,
}

impl Default for Engine {
    fn default() -> Self {
        Self {
            damper_ring: 0.005,
            damper_stiffness: 1.1e5,
            damper_damping: 7.0,
            pulley: 0.004,
            throw: 0.0035,
            nose_stiffness: 1.2e6,
            throw_stiffness: 1.0e6,
            flange_stiffness: 1.5e6,
            flywheel: 0.13,
            firing_order: [1, 3, 4, 2],
            // Full-load gasoline shape: a narrow firing pulse (peak ~12x the mean) has
            // harmonics of about twice the mean up to order 2, falling off above.
            gas_orders: vec![1.3, 2.1, 2.3, 2.2, 1.9, 1.6, 1.3, 1.0],
        }
    }
}

impl Engine {
    /// The crank angle at which cylinder `c` (1..=4) fires, in rad: its position in the
    /// firing order times the firing interval π (180°).
    pub fn firing_angle(&self, cylinder: usize) -> Option<f64> {
        self.firing_order
            .iter()
            .position(|&c| c == cylinder)
            .map(|p| p as f64 * PI)
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let ctx = "drivetrain engine";
        for (name, v) in [
            ("damper_ring", self.damper_ring),
            ("pulley", self.pulley),
            ("throw", self.throw),
            ("flywheel", self.flywheel),
            ("nose_stiffness", self.nose_stiffness),
            ("throw_stiffness", self.throw_stiffness),
            ("flange_stiffness", self.flange_stiffness),
            ("damper_stiffness", self.damper_stiffness),
        ] {
            check_positive(ctx, name, v)?;
        }
        check_non_negative(ctx, "damper_damping", self.damper_damping)?;
        let mut sorted = self.firing_order;
        sorted.sort_unstable();
        if sorted != [1, 2, 3, 4] {
            return Err(Error::InvalidParameter {
                context: ctx.into(),
                name: "firing_order".into(),
                value: f64::NAN,
                requirement: format!(
                    "a permutation of the cylinders 1, 2, 3, 4 (got {:?})",
                    self.firing_order
                ),
            });
        }
        for (j, a) in self.gas_orders.iter().enumerate() {
            crate::error::check_finite(ctx, &format!("gas_orders[{j}]"), *a)?;
        }
        Ok(())
    }
}

/// The clutch disc with its torsional damper: a soft idle stage `k_pre` acting over the whole
/// travel and the main springs `k_main` beyond the free angle `φ_f`:
/// `T(u) = k_pre u + k_main g(u) + c u̇`, `u = θ_flywheel - θ_hub`, with the dead zone
/// `g(u) = u ∓ φ_f` beyond `±φ_f` ([`Backlash`](crate::force::Backlash)); a linear spring
/// `k_pre + k_main` when `φ_f = 0`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClutchDamper {
    /// Clutch disc and hub (kg m²).
    pub hub: f64,
    /// Idle-stage stiffness (N m/rad).
    pub pre_stiffness: f64,
    /// Main-stage stiffness (N m/rad).
    pub main_stiffness: f64,
    /// Free angle φ_f (rad) of the idle stage; 0: a linear clutch.
    pub free_angle: f64,
    /// Viscous equivalent of the friction hysteresis (N m s/rad).
    pub damping: f64,
}

impl Default for ClutchDamper {
    /// Hub 0.004 kg m², 30 N m/rad idle stage over ±0.05 rad (±2.9°), 1200 N m/rad
    /// (21 N m/°) main stage, 2 N m s/rad.
    fn default() -> Self {
        Self {
            hub: 0.004,
            pre_stiffness: 30.0,
            main_stiffness: 1200.0,
            free_angle: 0.05,
            damping: 2.0,
        }
    }
}

impl ClutchDamper {
    /// `true` if the clutch is a nonlinear element (a free angle).
    pub fn is_nonlinear(&self) -> bool {
        self.free_angle > 0.0
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let ctx = "drivetrain clutch";
        check_positive(ctx, "hub", self.hub)?;
        check_non_negative(ctx, "pre_stiffness", self.pre_stiffness)?;
        check_positive(ctx, "main_stiffness", self.main_stiffness)?;
        check_non_negative(ctx, "free_angle", self.free_angle)?;
        check_non_negative(ctx, "damping", self.damping)
    }
}
