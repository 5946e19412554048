//! A gear stage: the mesh of a driving and a driven gear on their line of action.
//!
//! # Sign convention (used by every example, the README and docs/scenes.md)
//!
//! Every DOF's angle is positive in its own **running direction**: the direction it turns
//! when the drivetrain drives forward. A torque that drives is positive, a torque that resists
//! (road load, brake) is negative. For an external gear pair with base radii `r_b1`
//! (driving) and `r_b2` (driven) the rigid rotation is `r_b1 θ1 = r_b2 θ2`, and the stage's
//! coordinate is the **transmission error along the line of action**
//!
//! `u = r_b1 θ1 - r_b2 θ2`  (m),
//!
//! positive when the driving gear leads the driven one, i.e. when the drive flanks are loaded.
//! The mesh force `f(θ, u, u̇)` (N, along the line of action) acts back on the driving gear
//! with the torque `-r_b1 f` and on the driven gear with `+r_b2 f`: the element's weights are
//! `w = (r_b1, -r_b2)`. A loaded stage runs at `u > 0`; with backlash, contact is lost when
//! `|u|` falls below half the backlash, and the coast flanks touch at `u < -b/2`.
//!
//! With `ratio = i` instead of radii the stage works on `u = θ1 - i θ2` (rad): the weights are
//! `(1, -i)` and the stiffness is torsional, in N m/rad referred to the driving gear.

use crate::error::{check_finite, check_non_negative, Error, Result};
use crate::force::{Backlash, Flank, ForceLaw, MeshDamping, MeshProfile, MeshStiffness, MAX_TEETH};

/// A gear stage between a driving and a driven DOF (module documentation for the signs).
///
/// ```
/// use hbal::force::{MeshDamping, MeshProfile};
/// use hbal::model::GearStage;
/// use hbal::Model;
/// // A 20-tooth pinion (base radius 20 mm) driving a 50-tooth gear (50 mm).
/// let stage = GearStage::new("pinion", "gear", [0.02, 0.05], 20, MeshProfile::Constant { stiffness: 4e8 })
///     .with_damping(MeshDamping::Proportional(2e-6));
/// let model = Model::builder(&["pinion", "gear"])
///     .mass_diagonal(&[1e-3, 6.25e-3])
///     .stiffness(nalgebra::DMatrix::from_diagonal_element(2, 2, 1e4))
///     .gear_stage("mesh", stage)
///     .load("pinion", 0, 10.0, 0.0)   // drive torque, N m
///     .build()?;
/// let e = &model.elements()[0];
/// assert_eq!(e.weights(), &[(0, 0.02), (1, -0.05)]);   // u = r_b1 θ1 - r_b2 θ2
/// assert_eq!(e.gear_stage().unwrap().ratio(), 2.5);
/// # Ok::<(), hbal::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearStage {
    /// DOF of the driving gear.
    pub driving: String,
    /// DOF of the driven gear.
    pub driven: String,
    /// Base radii `[r_b1, r_b2]` of the driving and the driven gear, m (> 0). Give these or
    /// `ratio`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_radii: Option<[f64; 2]>,
    /// Transmission ratio `i = ω1/ω2 = r_b2/r_b1` (> 0), for a torsional stage on
    /// `u = θ1 - i θ2` (rad) instead of `base_radii`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio: Option<f64>,
    /// Teeth on the driving gear z1 (>= 1).
    pub teeth: u32,
    /// Revolutions of the driving gear per revolution of the reference shaft (default 1): a
    /// stage behind a ratio 2.5 from the engine has `shaft_order = 0.4`. The mesh runs
    /// `z1 · shaft_order / f` cycles per period of a fundamental of order `f`
    /// (`fundamental_order`), which must be a whole number where the mesh stiffness varies
    /// (any with a constant stiffness, which has no mesh order).
    #[serde(default = "one")]
    pub shaft_order: f64,
    /// The order `f` of the fundamental relative to the reference shaft (default 1; a scene
    /// sets it from its `fundamental.order`).
    #[serde(skip, default = "one")]
    pub fundamental_order: f64,
    /// Mesh phase φ0, rad (default 0): `φ = z1 shaft_order θ + φ0`.
    #[serde(default)]
    pub phase: f64,
    /// Mesh stiffness profile over the mesh cycle, N/m (N m/rad with `ratio`).
    pub stiffness: MeshProfile,
    /// Mesh damping, N s/m (N m s/rad with `ratio`), or proportional `β k(φ)`; default none.
    #[serde(default)]
    pub damping: MeshDamping,
    /// Total backlash along the line of action, m (rad with `ratio`; >= 0); default none.
    /// The flanks are free for `|u| < backlash/2`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backlash: Option<f64>,
}

fn one() -> f64 {
    1.0
}

impl GearStage {
    /// A stage with base radii `[r_b1, r_b2]` (m), `teeth` on the driving gear, stiffness
    /// profile (N/m), no damping, no backlash, one driving-gear revolution per period.
    pub fn new(
        driving: &str,
        driven: &str,
        base_radii: [f64; 2],
        teeth: u32,
        stiffness: MeshProfile,
    ) -> Self {
        Self {
            driving: driving.to_string(),
            driven: driven.to_string(),
            base_radii: Some(base_radii),
            ratio: None,
            teeth,
            shaft_order: 1.0,
            fundamental_order: 1.0,
            phase: 0.0,
            stiffness,
            damping: MeshDamping::default(),
            backlash: None,
        }
    }

    /// Sets the mesh damping.
    pub fn with_damping(mut self, damping: MeshDamping) -> Self {
        self.damping = damping;
        self
    }

    /// Sets the total backlash along the line of action (m).
    pub fn with_backlash(mut self, backlash: f64) -> Self {
        self.backlash = Some(backlash);
        self
    }

    /// Sets the driving gear's revolutions per period of the fundamental.
    pub fn with_shaft_order(mut self, shaft_order: f64) -> Self {
        self.shaft_order = shaft_order;
        self
    }

    /// Sets the order of the fundamental relative to the reference shaft.
    pub fn with_fundamental_order(mut self, order: f64) -> Self {
        self.fundamental_order = order;
        self
    }

    /// Sets the mesh phase φ0 (rad).
    pub fn with_phase(mut self, phase: f64) -> Self {
        self.phase = phase;
        self
    }

    /// The weights `(r_b1, -r_b2)` of `u = r_b1 θ1 - r_b2 θ2` (`(1, -i)` with a ratio).
    pub fn lever_arms(&self) -> [f64; 2] {
        match (self.base_radii, self.ratio) {
            (Some([r1, r2]), _) => [r1, r2],
            (None, Some(i)) => [1.0, i],
            (None, None) => [f64::NAN, f64::NAN],
        }
    }

    /// The transmission ratio `i = r_b2 / r_b1` (speed of the driving over the driven gear).
    pub fn ratio(&self) -> f64 {
        let [r1, r2] = self.lever_arms();
        r2 / r1
    }

    /// Mesh cycles per period of the fundamental, `z1 · shaft_order / f`, if it is a whole
    /// number >= 1 (to 1e-9).
    pub fn mesh_order(&self) -> Option<u32> {
        let z = self.mesh_cycles();
        let r = z.round();
        (z.is_finite() && r >= 1.0 && r <= u32::MAX as f64 && (z - r).abs() <= 1e-9 * z.max(1.0))
            .then_some(r as u32)
    }

    /// Mesh cycles per period of the fundamental, `z1 · shaft_order / f`, as a real number.
    fn mesh_cycles(&self) -> f64 {
        self.teeth as f64 * self.shaft_order / self.fundamental_order
    }

    /// Checks every field; `context` names the element.
    pub fn validate(&self, context: &str) -> Result<()> {
        match (self.base_radii, self.ratio) {
            (Some(_), Some(_)) | (None, None) => {
                return Err(Error::InvalidElement {
                    context: context.into(),
                    reason: "give exactly one of `base_radii` and `ratio`".into(),
                })
            }
            (Some([r1, r2]), None) => {
                check_positive(context, "base_radii[0]", r1)?;
                check_positive(context, "base_radii[1]", r2)?;
            }
            (None, Some(i)) => check_positive(context, "ratio", i)?,
        }
        if self.driving == self.driven {
            return Err(Error::InvalidElement {
                context: context.into(),
                reason: format!("`driving` and `driven` are the same DOF `{}`", self.driving),
            });
        }
        crate::force::check_teeth(context, self.teeth)?;
        check_positive(context, "shaft_order", self.shaft_order)?;
        check_positive(context, "fundamental_order", self.fundamental_order)?;
        // A constant mesh stiffness does not vary with the mesh cycle: any real ratio and
        // shaft order (the marine line's 9.4094), the mesh order is not a harmonic.
        let z = self.mesh_cycles();
        let varies = self.stiffness.time_order(1).is_some();
        if varies && z > MAX_TEETH as f64 + 0.5 {
            return Err(Error::invalid(
                context,
                "shaft_order",
                self.shaft_order,
                format!(
                    "such that the mesh cycles per period of the fundamental, teeth x \
                     shaft_order / fundamental order = {} x {} / {} = {z:.6e}, are at most \
                     {MAX_TEETH} (the highest order any harmonic basis resolves): make the mesh \
                     order the fundamental with `fundamental.order`",
                    self.teeth, self.shaft_order, self.fundamental_order
                ),
            ));
        }
        if varies && self.mesh_order().is_none() {
            return Err(Error::invalid(
                context,
                "shaft_order",
                self.shaft_order,
                format!(
                    "such that teeth x shaft_order ({} x {}) is a whole multiple of the \
                     fundamental's order {} (choose the fundamental so that the mesh order is a \
                     harmonic, or put the scene on several base frequencies with \
                     `harmonics.bases = \"torus\"`)",
                    self.teeth, self.shaft_order, self.fundamental_order
                ),
            ));
        }
        check_finite(context, "phase", self.phase)?;
        if let Some(b) = self.backlash {
            check_non_negative(context, "backlash", b)?;
        }
        self.stiffness.validate(context)?;
        self.damping.validate(context)
    }

    /// The element's `(DOF, weight)` pairs and its mesh law: a [`MeshStiffness`] without
    /// backlash, a [`Backlash`] contact (drive flank) with it, whose contact damping is the
    /// constant damping or `β k̄` with the mean stiffness `k̄` for proportional damping.
    /// Call [`GearStage::validate`] first.
    pub fn element(&self) -> ([(&str, f64); 2], Box<dyn ForceLaw>) {
        let [r1, r2] = self.lever_arms();
        let weights = [(self.driving.as_str(), r1), (self.driven.as_str(), -r2)];
        // A constant stiffness has no mesh order: one cycle per period, whatever the teeth.
        let varies = self.stiffness.time_order(1).is_some();
        let z = if varies {
            self.mesh_order().unwrap_or(1)
        } else {
            1
        };
        let law: Box<dyn ForceLaw> = match self.backlash {
            None => Box::new(
                MeshStiffness::new(z, self.stiffness.clone(), self.damping).with_phase(self.phase),
            ),
            Some(b) => Box::new(Backlash {
                half_backlash: 0.5 * b,
                stiffness: self.stiffness.clone(),
                teeth: z,
                phase: self.phase,
                contact_damping: self.damping.value(self.stiffness.mean()),
                flank: Flank::Drive,
            }),
        };
        (weights, law)
    }
}

fn check_positive(context: &str, name: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(context, name, v, "finite and > 0"))
    }
}
