//! The parts of a [`Drivetrain`](super::Drivetrain) behind the clutch: shafts, gear pairs,
//! wheels and vehicle, with realistic default values and the formulas that turn geometry into
//! inertias and stiffnesses.
//!
//! Units: SI throughout (m, kg, s, rad; inertias in kg m², torsional stiffness in N m/rad,
//! torsional damping in N m s/rad, mesh stiffness along the line of action in N/m).

use crate::error::{check_non_negative, check_positive, Error, Result};
use std::f64::consts::PI;

/// Shear modulus of steel G (Pa).
pub const STEEL_SHEAR_MODULUS: f64 = 80e9;
/// Density of steel ρ (kg/m³).
pub const STEEL_DENSITY: f64 = 7850.0;

/// A uniform steel shaft (solid or tube), discretised into `segments` equal torsional
/// elements.
///
/// With the polar area moment `Jp = π (D⁴ - d⁴) / 32` (m⁴), the whole shaft has the torsional
/// stiffness `k = G Jp / L` (N m/rad) and the mass moment of inertia `J = ρ Jp L` (kg m²). A
/// segment of length `L/e` has stiffness `e k` and inertia `J/e`, lumped half on each of its
/// two nodes: the classic lumped-mass finite element, exact in its static twist `T L / (G Jp)`
/// and accurate up to frequencies well below the segment's own `√(e k / (J/e))`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Shaft {
    /// Length L (m).
    pub length: f64,
    /// Outer diameter D (m).
    pub diameter: f64,
    /// Bore d (m), 0 for a solid shaft.
    pub bore: f64,
    /// Number of torsional elements e (>= 1).
    pub segments: usize,
}

impl Shaft {
    /// A solid shaft of length `length` and diameter `diameter` (m), one segment.
    pub fn solid(length: f64, diameter: f64) -> Self {
        Self {
            length,
            diameter,
            bore: 0.0,
            segments: 1,
        }
    }

    /// A tube of length `length`, outer diameter `diameter` and bore `bore` (m), one segment.
    pub fn tube(length: f64, diameter: f64, bore: f64) -> Self {
        Self {
            length,
            diameter,
            bore,
            segments: 1,
        }
    }

    /// Polar area moment `Jp = π (D⁴ - d⁴) / 32` (m⁴).
    pub fn polar_moment(&self) -> f64 {
        PI * (self.diameter.powi(4) - self.bore.powi(4)) / 32.0
    }

    /// Torsional stiffness of the whole shaft `G Jp / L` (N m/rad).
    pub fn stiffness(&self) -> f64 {
        STEEL_SHEAR_MODULUS * self.polar_moment() / self.length
    }

    /// Mass moment of inertia of the whole shaft `ρ Jp L` (kg m²).
    pub fn inertia(&self) -> f64 {
        STEEL_DENSITY * self.polar_moment() * self.length
    }

    /// Static twist `T L / (G Jp)` (rad) under the torque `torque` (N m).
    pub fn twist(&self, torque: f64) -> f64 {
        torque / self.stiffness()
    }

    pub(crate) fn validate(&self, context: &str) -> Result<()> {
        check_positive(context, "length", self.length)?;
        check_positive(context, "diameter", self.diameter)?;
        check_non_negative(context, "bore", self.bore)?;
        if self.bore >= self.diameter {
            return Err(Error::invalid(
                context,
                "bore",
                self.bore,
                format!("below the diameter {}", self.diameter),
            ));
        }
        if self.segments == 0 {
            return Err(Error::invalid(context, "segments", 0.0, "an integer >= 1"));
        }
        Ok(())
    }
}

/// A spur gear pair: its mesh is the transmission error along the line of action
/// `u = r_p θ_p - r_g θ_g` (m), every angle counted positive in its own shaft's direction of
/// rotation, so `u > 0` when the pinion leads (drive flank).
///
/// Two elements act on `u`:
/// - the loaded mesh, `f = k(φ) u + β k(φ) u̇` ([`MeshStiffness`](crate::force::MeshStiffness)),
///   a rectangular one-/two-tooth profile over the mesh angle φ (one cycle per tooth). Per
///   unit face width (ISO 6336 orders of magnitude) a single tooth pair has `c' ≈ 14 N/(mm µm)`
///   = 1.4e10 N/m², and with contact ratio 1.5 and 2.6e10 N/m² for two pairs the mean is the
///   mesh stiffness `c_γ = 20 N/(mm µm)`. Linear time-varying: it assumes the flanks stay in
///   contact, which the static drive torque ensures;
/// - the tip-relief contact, `f = k_r g(u)` with the dead zone `g` of half width `C_a`
///   ([`Backlash`](crate::force::Backlash)): once the deflection exceeds the tip relief
///   `C_a ≈ 15 µm`, the relieved tip of the next tooth pair comes into contact early and the
///   mesh stiffens (a load-dependent contact ratio); the same on the coast side.
///
/// Pitch radii `r = m z / 2` (module m), gear inertias of solid steel discs
/// `J = π ρ b r⁴ / 2` (face width b).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GearPair {
    /// Pinion (driving gear) teeth z_p.
    pub pinion_teeth: u32,
    /// Gear (driven) teeth z_g; the ratio is `z_g / z_p`.
    pub gear_teeth: u32,
    /// Module m (m).
    pub module: f64,
    /// Face width b (m).
    pub face_width: f64,
    /// Contact ratio ε in [1, 2].
    pub contact_ratio: f64,
    /// One-tooth-pair stiffness per face width (N/m per m).
    pub one_tooth: f64,
    /// Two-tooth-pair stiffness per face width (N/m per m).
    pub two_tooth: f64,
    /// Mesh damping `d = β k(φ)`, β in s (2e-6 s: ζ ≈ βω/2 ≈ 0.05 at a 5e4 rad/s mesh mode).
    pub mesh_beta: f64,
    /// Tip relief C_a (m): half width of the dead zone of the tip-relief contact.
    pub tip_relief: f64,
    /// Stiffness of the tip-relief contact per face width (N/m per m).
    pub relief_stiffness: f64,
}

impl GearPair {
    /// A pair with `pinion_teeth : gear_teeth`, module and face width in m, and the default
    /// mesh data (ε 1.5, 1.4e10 / 2.6e10 N/m², β 2e-6 s, C_a 15 µm, 0.7e10 N/m²).
    pub fn new(pinion_teeth: u32, gear_teeth: u32, module: f64, face_width: f64) -> Self {
        Self {
            pinion_teeth,
            gear_teeth,
            module,
            face_width,
            contact_ratio: 1.5,
            one_tooth: 1.4e10,
            two_tooth: 2.6e10,
            mesh_beta: 2e-6,
            tip_relief: 15e-6,
            relief_stiffness: 0.7e10,
        }
    }

    /// Ratio `i = z_g / z_p` (gear speed = pinion speed / i, gear torque = i · pinion torque).
    pub fn ratio(&self) -> f64 {
        self.gear_teeth as f64 / self.pinion_teeth as f64
    }

    /// Pinion pitch radius `m z_p / 2` (m).
    pub fn pinion_radius(&self) -> f64 {
        self.module * self.pinion_teeth as f64 / 2.0
    }

    /// Gear pitch radius `m z_g / 2` (m).
    pub fn gear_radius(&self) -> f64 {
        self.module * self.gear_teeth as f64 / 2.0
    }

    /// Inertia of a solid steel disc of radius `r` and the face width: `π ρ b r⁴ / 2` (kg m²).
    pub fn disc_inertia(&self, r: f64) -> f64 {
        PI * STEEL_DENSITY * self.face_width * r.powi(4) / 2.0
    }

    /// Mean mesh stiffness `((ε-1) k2 + (2-ε) k1) b` (N/m).
    pub fn mean_stiffness(&self) -> f64 {
        let e = self.contact_ratio;
        ((e - 1.0) * self.two_tooth + (2.0 - e) * self.one_tooth) * self.face_width
    }

    pub(crate) fn validate(&self, context: &str) -> Result<()> {
        for (name, z) in [
            ("pinion_teeth", self.pinion_teeth),
            ("gear_teeth", self.gear_teeth),
        ] {
            if z == 0 {
                return Err(Error::invalid(context, name, 0.0, "an integer >= 1"));
            }
        }
        check_positive(context, "module", self.module)?;
        check_positive(context, "face_width", self.face_width)?;
        check_non_negative(context, "mesh_beta", self.mesh_beta)?;
        check_non_negative(context, "tip_relief", self.tip_relief)?;
        check_non_negative(context, "relief_stiffness", self.relief_stiffness)
        // The profile (stiffnesses, contact ratio) is validated by the mesh element itself.
    }
}

/// A gearbox stage: a gear pair and the shaft that carries its gear to the next pinion.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GearStage {
    /// The gear pair.
    pub pair: GearPair,
    /// The shaft from its gear to the next stage's pinion (or the propeller shaft).
    pub shaft: Shaft,
}

/// Wheels, tyres and the vehicle, in wheel coordinates.
///
/// The vehicle's translation is a rotation of the wheel: inertia `m r²`. Each tyre couples
/// its wheel to the vehicle by a torsional spring (belt and sidewall) and the slip damping
/// `C_x r² / v`. Free-free models are not supported yet (issue 11), so the vehicle is
/// grounded by a soft spring `k_g`: with the loads balanced it carries no static torque, and
/// the rigid-body mode sits at `√(k_g / J_total)` ≈ 1.8 rad/s (0.3 Hz), a twentieth of the
/// shuffle mode; at harmonic 1 it adds `k_g / (m r² Ω²)` ≈ 3e-4 (2000 rpm) to the vehicle's
/// dynamic stiffness. Much softer is worse, not better: the static rigid-body position is set
/// by the balance of the loads against `k_g` alone, so round-off grows as `1 / k_g` (at 50
/// N m/rad the full formulation's residual stalls at 1e-13 and the full and condensed
/// solutions agree to 6e-10 only).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Vehicle {
    /// Wheel with rim, hub and brake disc, each (kg m²).
    pub wheel: f64,
    /// Torsional tyre stiffness, each (N m/rad).
    pub tyre_stiffness: f64,
    /// Tyre slip damping, each (N m s/rad).
    pub tyre_damping: f64,
    /// Vehicle mass (kg).
    pub mass: f64,
    /// Rolling radius r (m).
    pub wheel_radius: f64,
    /// Road-load damping at the vehicle (N m s/rad).
    pub road_damping: f64,
    /// Grounding spring k_g at the vehicle (N m/rad).
    pub ground_stiffness: f64,
}

impl Default for Vehicle {
    /// 1.0 kg m² wheels, 2e4 N m/rad and 500 N m s/rad tyres (slip stiffness `C_x` = 1e5 N
    /// at v ≈ 20 m/s), 1500 kg on 0.31 m, 2 N m s/rad road load, 500 N m/rad ground.
    fn default() -> Self {
        Self {
            wheel: 1.0,
            tyre_stiffness: 2e4,
            tyre_damping: 500.0,
            mass: 1500.0,
            wheel_radius: 0.31,
            road_damping: 2.0,
            ground_stiffness: 500.0,
        }
    }
}

impl Vehicle {
    /// The vehicle's inertia at the wheels `m r²` (kg m²).
    pub fn inertia(&self) -> f64 {
        self.mass * self.wheel_radius * self.wheel_radius
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let ctx = "drivetrain vehicle";
        for (name, v) in [
            ("wheel", self.wheel),
            ("tyre_stiffness", self.tyre_stiffness),
            ("mass", self.mass),
            ("wheel_radius", self.wheel_radius),
            ("ground_stiffness", self.ground_stiffness),
        ] {
            check_positive(ctx, name, v)?;
        }
        check_non_negative(ctx, "tyre_damping", self.tyre_damping)?;
        check_non_negative(ctx, "road_damping", self.road_damping)
    }
}
