//! A torsional vehicle drivetrain whose size scales from about 10 to 10⁵ DOFs by shaft
//! discretisation: the benchmark model of large-model harmonic balance (issue 10).
//!
//! ```text
//!  damper ring ─ pulley ─ throw 1 ─ throw 2 ─ throw 3 ─ throw 4 ─ flywheel ═ clutch damper ═ hub
//!  hub ── input shaft ── pinion 1 ⋈ gear 1 ── shaft 1 ── pinion 2 ⋈ gear 2 ── ... ── propeller
//!  shaft ── final-drive pinion ⋈ ring gear / differential ─┬─ left half shaft ── wheel ~ tyre ~ vehicle
//!                                                          └─ right half shaft ── wheel ~ tyre ~┘
//! ```
//!
//! A 4-cylinder, 4-stroke engine (crank throws, torsional vibration damper, flywheel; parts in
//! [`Engine`]), a two-stage clutch damper ([`ClutchDamper`]), a gear train of m meshes (m - 1
//! gearbox stages, [`GearStage`], and the final drive), a locked differential (equal wheel
//! speeds: with symmetric loads an open differential's antisymmetric mode is not excited),
//! two half shafts, wheels, tyres and the vehicle ([`Vehicle`]). Every shaft is a uniform steel
//! [`Shaft`] of `segments` lumped torsional elements; the crank sections are lumped.
//!
//! **Equations.** `M q̈ + D q̇ + K q + Σ_e w_e f_e(θ, w_eᵀq, w_eᵀq̇) = T(θ)` with q the absolute
//! angles (rad), every one counted positive in its own shaft's direction of rotation (a
//! forward drive turns every DOF positive). M is diagonal (lumped inertias, kg m²); K and D
//! (N m/rad, N m s/rad) hold the crank, shafts, damper rubber, clutch idle stage, tyres and the
//! ground spring, with material damping `d = β k` on every crank and shaft section. The
//! elements: per mesh a rectangular mesh stiffness and a tip-relief contact on the
//! transmission error `u = r_p θ_p - r_g θ_g` (m) ([`GearPair`]), and the clutch main stage on
//! `θ_flywheel - θ_hub` if it has a free angle.
//!
//! **Fundamental.** hbal's loads and meshes are whole orders of one fundamental, and a
//! 4-stroke engine fires every second revolution: the fundamental Ω is **half the crank
//! speed** ([`Drivetrain::fundamental`]), so crank order ν is harmonic 2ν (gas orders 0.5, 1,
//! ..., 4 are harmonics 1..8, the dominant 2nd order of four cylinders is harmonic 4). A mesh
//! whose pinion has `z_p` teeth on a shaft turning at `s` times the crank speed meshes at
//! crank order `z_p s`, harmonic `2 z_p s`, which must be a whole number (checked). The
//! fundamental cannot be the mesh frequency instead: the engine orders would not be whole
//! multiples of it. The default teeth keep every mesh at or below harmonic 32 (m = 4: mesh
//! harmonics 32, 32, 20, 12), so H = 32 is the smallest basis (`HarmonicBalance::new`
//! refuses less, [`Error::ElementOrderTooHigh`]); it resolves the
//! first harmonic of the fastest mesh's stiffness variation, H = 64 or 128 its second and
//! fourth. That needs a first pinion of at most 16 teeth on the input shaft: few, but real
//! (low-gear pinions have 11 to 16). [`Drivetrain::coarse_teeth`] divides every tooth count
//! (keeping radii and ratios) for tests at small H.
//!
//! **Loads.** The mean drive torque `T` (N m), a quarter on each throw, balanced by
//! `-T i` at the vehicle (i the overall ratio), so the ground spring carries no static torque;
//! and per cylinder c the gas-torque harmonics `a_j (T/4) cos(j(θ - α_c/2))`, j = 1, 2, ...,
//! with `α_c` the crank angle at which c fires (firing order 1-3-4-2, every 180°): crank orders
//! that are not multiples of 2 (harmonics not multiples of 4) cancel on a rigid crank and act
//! only through its twist.
//!
//! **Size.** `n = 10 + e_in + e_prop + e_left + e_right + Σ_j (1 + e_j)` for `e` segments per
//! shaft (20 DOFs at one segment each with m = 4, 14 with m = 1);
//! [`Drivetrain::with_dofs`] spreads segments over the shafts by length to reach any larger n.
//! The model is built from triplets ([`ModelBuilder::mass_triplets`](crate::model::ModelBuilder::mass_triplets)),
//! never as dense matrices here.
//!
//! ```
//! use hbal::catalog::Drivetrain;
//! use hbal::{Formulation, HarmonicBalance, HarmonicBasis, Newton};
//! let drivetrain = Drivetrain::default().with_dofs(40);
//! let model = drivetrain.model()?;
//! assert_eq!(model.n_dofs(), 40);
//! assert_eq!(drivetrain.max_order()?, 32);
//! let basis = HarmonicBasis::new(drivetrain.fundamental(2000.0), 32)?;
//! let hb = HarmonicBalance::with_formulation(&model, basis, Formulation::Condensed)?;
//! assert_eq!(hb.unknown_names().len(), 5); // 4 meshes and the clutch
//! # Ok::<(), hbal::Error>(())
//! ```

mod assembly;
mod engine;
mod parts;

pub use engine::{ClutchDamper, Engine};
pub use parts::{GearPair, GearStage, Shaft, Vehicle, STEEL_DENSITY, STEEL_SHEAR_MODULUS};

use crate::error::{check_finite, check_non_negative, check_positive, Error, Result};
use crate::model::Model;
use std::f64::consts::PI;

/// The drivetrain's parameters (see the [module](self) documentation); `Default` is a 150 N m
/// drive through m = 4 meshes with one segment per shaft (20 DOFs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Drivetrain {
    /// Engine.
    pub engine: Engine,
    /// Clutch damper.
    pub clutch: ClutchDamper,
    /// Gearbox input shaft, from the clutch hub to the first pinion.
    pub input_shaft: Shaft,
    /// Gearbox stages, in the order the power flows (m - 1 of them).
    pub gearbox: Vec<GearStage>,
    /// Propeller shaft, from the gearbox output to the final-drive pinion.
    pub propeller_shaft: Shaft,
    /// Final drive (hypoid pair taken as an equivalent spur pair).
    pub final_drive: GearPair,
    /// Differential carrier besides the ring gear (kg m²).
    pub differential: f64,
    /// Left and right half shafts.
    pub half_shafts: [Shaft; 2],
    /// Wheels, tyres and vehicle.
    pub vehicle: Vehicle,
    /// Material damping of crank and shaft sections, `d = β k`, β in s (2e-5 s: ζ = βω/2 ≈
    /// 0.05 at the crank's first mode, 5.3e3 rad/s).
    pub shaft_beta: f64,
    /// Mean engine torque T (N m).
    pub drive_torque: f64,
}

impl Default for Drivetrain {
    fn default() -> Self {
        Self {
            engine: Engine::default(),
            clutch: ClutchDamper::default(),
            input_shaft: Shaft::solid(0.25, 0.030),
            gearbox: (1..4).map(default_stage).collect(),
            propeller_shaft: Shaft::tube(1.4, 0.070, 0.066),
            final_drive: GearPair::new(12, 40, 4.5e-3, 0.030),
            differential: 0.015,
            half_shafts: [Shaft::solid(0.60, 0.028), Shaft::solid(0.65, 0.028)],
            vehicle: Vehicle::default(),
            shaft_beta: 2e-5,
            drive_torque: 150.0,
        }
    }
}

/// Gearbox stage `j` (from 1) of [`Drivetrain::with_meshes`]: a 16:24 constant mesh, a 24:32
/// gear, then 1:1 transfer gears of 20, 24, 28, 20, ... teeth (mesh harmonics 32, 32, 20, 24,
/// 28, ...; every tooth count divisible by 4).
fn default_stage(j: usize) -> GearStage {
    match j {
        1 => GearStage {
            pair: GearPair::new(16, 24, 3.5e-3, 0.020),
            shaft: Shaft::solid(0.12, 0.040),
        },
        2 => GearStage {
            pair: GearPair::new(24, 32, 3.0e-3, 0.022),
            shaft: Shaft::solid(0.20, 0.035),
        },
        _ => {
            let z = [20, 24, 28][(j - 3) % 3];
            GearStage {
                pair: GearPair::new(z, z, 3.5e-3, 0.025),
                shaft: Shaft::solid(0.10, 0.040),
            }
        }
    }
}

impl Drivetrain {
    /// The gear train with `meshes` meshes: `meshes - 1` gearbox stages (a constant mesh, a
    /// gear, then transfer gears) and the final drive; the new stages' shafts have one
    /// segment, the other shafts keep theirs (call [`Drivetrain::with_dofs`] afterwards).
    /// Overall ratio 3.33 (m = 1, a direct gear), 5.0 (m = 2), 6.67 (m >= 3).
    pub fn with_meshes(mut self, meshes: usize) -> Result<Self> {
        if meshes == 0 {
            return Err(Error::invalid(
                "drivetrain",
                "meshes",
                0.0,
                "at least 1 (the final drive)",
            ));
        }
        self.gearbox = (1..meshes).map(default_stage).collect();
        Ok(self)
    }

    /// Segments spread over all shafts in proportion to their lengths (about equal segment
    /// lengths, at least one per shaft) so that the model has exactly `n` DOFs, or the
    /// smallest possible number if `n` is below it.
    pub fn with_dofs(mut self, n: usize) -> Self {
        let stages = self.gearbox.len();
        let mut shafts = self.shafts_mut();
        let base = FIXED_DOFS + stages + shafts.len();
        let extra = n.saturating_sub(base);
        let lengths: Vec<f64> = shafts.iter().map(|s| s.length.max(0.0)).collect();
        let total: f64 = lengths.iter().sum();
        let share = |l: f64| {
            if total > 0.0 {
                extra as f64 * l / total
            } else {
                extra as f64 / lengths.len() as f64
            }
        };
        let mut counts: Vec<usize> = lengths.iter().map(|&l| share(l).floor() as usize).collect();
        // Largest remainders take the segments left over by rounding down.
        let mut order: Vec<usize> = (0..counts.len()).collect();
        order.sort_by(|&a, &b| {
            let fa = share(lengths[a]) - counts[a] as f64;
            let fb = share(lengths[b]) - counts[b] as f64;
            fb.total_cmp(&fa)
        });
        let left = extra - counts.iter().sum::<usize>().min(extra);
        for &i in order.iter().cycle().take(left) {
            counts[i] += 1;
        }
        for (s, c) in shafts.iter_mut().zip(counts) {
            s.segments = 1 + c;
        }
        self
    }

    /// Every tooth count divided by `divisor` and every module multiplied by it: the same
    /// radii, ratios and inertias, mesh harmonics divided by `divisor` (`coarse_teeth(4)`:
    /// at most harmonic 8, so H = 8 works). A device for tests and cost measurements at small
    /// H, not a real gear. Errors if a tooth count is not divisible.
    pub fn coarse_teeth(mut self, divisor: u32) -> Result<Self> {
        if divisor == 0 {
            return Err(Error::invalid("drivetrain", "divisor", 0.0, ">= 1"));
        }
        let pairs = self
            .gearbox
            .iter_mut()
            .map(|s| &mut s.pair)
            .chain(std::iter::once(&mut self.final_drive));
        for (j, p) in pairs.enumerate() {
            for z in [&mut p.pinion_teeth, &mut p.gear_teeth] {
                if *z % divisor != 0 {
                    return Err(Error::invalid(
                        format!("drivetrain mesh {}", j + 1),
                        "teeth",
                        *z as f64,
                        format!("divisible by {divisor}"),
                    ));
                }
                *z /= divisor;
            }
            p.module *= divisor as f64;
        }
        Ok(self)
    }

    /// Number of DOFs of [`Drivetrain::model`].
    pub fn n_dofs(&self) -> usize {
        let segments: usize = self.shafts().iter().map(|s| s.segments).sum();
        FIXED_DOFS + self.gearbox.len() + segments
    }

    /// Number of meshes m (gearbox stages and the final drive).
    pub fn meshes(&self) -> usize {
        self.gearbox.len() + 1
    }

    /// Number of coordinates of the exact condensation: one per mesh (its mesh stiffness and
    /// tip-relief contact share it), plus the clutch if it has a free angle.
    pub fn condensed_coordinates(&self) -> usize {
        self.meshes() + usize::from(self.clutch.is_nonlinear())
    }

    /// The model's fundamental at engine speed `rpm`: half the crank speed, `π rpm / 60`
    /// (rad/s).
    pub fn fundamental(&self, rpm: f64) -> f64 {
        PI * rpm / 60.0
    }

    /// Overall ratio `i = Π z_g / z_p` (crank speed / wheel speed).
    pub fn total_ratio(&self) -> f64 {
        self.pairs().map(GearPair::ratio).product()
    }

    /// The mesh harmonics (mesh cycles per period of the fundamental), in the order of the
    /// power flow: `2 z_p s` for a pinion on a shaft at `s` times the crank speed. Errors if
    /// one is not a whole number.
    pub fn mesh_orders(&self) -> Result<Vec<usize>> {
        // Shaft speed s = num / den (reduced) relative to the crank.
        let (mut num, mut den) = (1u128, 1u128);
        let mut orders = Vec::with_capacity(self.meshes());
        for (j, p) in self.pairs().enumerate() {
            let (zp, zg) = (p.pinion_teeth as u128, p.gear_teeth as u128);
            if zp == 0 || zg == 0 {
                return Err(Error::invalid(
                    format!("drivetrain mesh {}", j + 1),
                    "teeth",
                    0.0,
                    "an integer >= 1",
                ));
            }
            let order = num.saturating_mul(2 * zp);
            if order % den != 0 || order / den > u32::MAX as u128 {
                return Err(Error::invalid(
                    format!("drivetrain mesh {}", j + 1),
                    "pinion_teeth",
                    zp as f64,
                    format!(
                        "such that the mesh frequency 2 z_p s (s = {num}/{den} of the crank speed) is a whole harmonic of half the crank speed, got {:.4}",
                        order as f64 / den as f64
                    ),
                ));
            }
            orders.push((order / den) as usize);
            let (Some(a), Some(b)) = (num.checked_mul(zp), den.checked_mul(zg)) else {
                return Err(Error::invalid(
                    format!("drivetrain mesh {}", j + 1),
                    "gear_teeth",
                    zg as f64,
                    "such that the shaft speed ratios stay representable",
                ));
            };
            let g = gcd(a, b);
            (num, den) = (a / g, b / g);
        }
        Ok(orders)
    }

    /// The highest order present: of the gas-torque harmonics and of the meshes. A basis
    /// needs at least this many harmonics.
    pub fn max_order(&self) -> Result<usize> {
        let meshes = self.mesh_orders()?;
        Ok(meshes
            .into_iter()
            .fold(self.engine.gas_orders.len(), usize::max))
    }

    /// Builds the model (DOF names, triplets, elements and loads; see the module
    /// documentation), after checking every parameter.
    pub fn model(&self) -> Result<Model> {
        self.validate()?;
        assembly::build(self)
    }

    /// The gear pairs in the order of the power flow (the final drive last).
    fn pairs(&self) -> impl Iterator<Item = &GearPair> {
        self.gearbox
            .iter()
            .map(|s| &s.pair)
            .chain(std::iter::once(&self.final_drive))
    }

    /// The discretised shafts: input, stage shafts, propeller shaft, half shafts.
    fn shafts(&self) -> Vec<&Shaft> {
        let mut v = vec![&self.input_shaft];
        v.extend(self.gearbox.iter().map(|s| &s.shaft));
        v.push(&self.propeller_shaft);
        v.extend(self.half_shafts.iter());
        v
    }

    fn shafts_mut(&mut self) -> Vec<&mut Shaft> {
        let mut v = vec![&mut self.input_shaft];
        v.extend(self.gearbox.iter_mut().map(|s| &mut s.shaft));
        v.push(&mut self.propeller_shaft);
        v.extend(self.half_shafts.iter_mut());
        v
    }

    fn validate(&self) -> Result<()> {
        self.engine.validate()?;
        self.clutch.validate()?;
        self.vehicle.validate()?;
        self.input_shaft.validate("drivetrain input shaft")?;
        for (j, s) in self.gearbox.iter().enumerate() {
            s.pair.validate(&format!("drivetrain mesh {}", j + 1))?;
            s.shaft.validate(&format!("drivetrain shaft {}", j + 1))?;
        }
        self.final_drive
            .validate(&format!("drivetrain mesh {} (final drive)", self.meshes()))?;
        self.propeller_shaft
            .validate("drivetrain propeller shaft")?;
        self.half_shafts[0].validate("drivetrain left half shaft")?;
        self.half_shafts[1].validate("drivetrain right half shaft")?;
        check_positive("drivetrain", "differential", self.differential)?;
        check_non_negative("drivetrain", "shaft_beta", self.shaft_beta)?;
        check_finite("drivetrain", "drive_torque", self.drive_torque)?;
        self.mesh_orders().map(|_| ())
    }
}

/// DOFs besides the shaft nodes and the gears of the gearbox stages: damper ring, pulley, four
/// throws, flywheel, clutch hub, differential carrier, vehicle.
const FIXED_DOFS: usize = 10;

fn gcd(mut a: u128, mut b: u128) -> u128 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}
