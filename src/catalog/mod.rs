//! Published benchmark models, built the same way in examples, tests and benchmarks.

use crate::error::Result;
use crate::force::{Backlash, CubicSpring, MeshDamping, MeshProfile, MeshStiffness};
use crate::model::Model;
use nalgebra::DMatrix;
use std::f64::consts::TAU;

pub mod drivetrain;
pub use drivetrain::Drivetrain;
mod mesh_chain;
pub use mesh_chain::MeshChain;
mod two_stage_train;
pub use two_stage_train::TwoStageTrain;

/// The paper's two-shaft model (Bauer et al. 2021, section 4) with the values of hbal's issue 2
/// (shared with `../shared/reference/seed_rect_6000rpm.json`).
///
/// One DOF, the relative rotation `q = α - Ω t` of the gear shaft:
/// `M q̈ + D(t) q̇ + K(t) q = L0 + L1 cos(4 Ω t)`, with 4 mesh cycles per revolution, `K(t)`
/// alternating between two-tooth contact (first half of each mesh cycle, from mesh angle 0)
/// and one-tooth contact, `D(t) = β K(t)`, and `L1 = M e (4Ω)²`.
///
/// The model's fundamental is the **mesh** frequency `4Ω` (its harmonic k is shaft order 4k):
/// the response has no other orders, so this is all a scene needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoShaft {
    /// Shaft speed in rpm.
    pub rpm: f64,
}

impl TwoShaft {
    /// Inertia M (kg m²).
    pub const INERTIA: f64 = 1e-3;
    /// One-tooth mesh stiffness (N m/rad).
    pub const ONE_TOOTH: f64 = 2.5e5;
    /// Two-tooth mesh stiffness (N m/rad).
    pub const TWO_TOOTH: f64 = 5e5;
    /// Contact ratio.
    pub const CONTACT_RATIO: f64 = 1.5;
    /// Stiffness-proportional damping β (s).
    pub const BETA: f64 = 5.1639777949e-6;
    /// Static load L0 (N m).
    pub const L0: f64 = 10.0;
    /// Excitation angle e (rad), `L1 = M e (4Ω)²`.
    pub const E: f64 = 5e-4;
    /// Mesh cycles per revolution.
    pub const TEETH: u32 = 4;

    /// At `rpm`.
    pub fn new(rpm: f64) -> Self {
        Self { rpm }
    }

    /// Shaft speed Ω in rad/s.
    pub fn shaft_omega(&self) -> f64 {
        self.rpm * TAU / 60.0
    }

    /// The model's fundamental, the mesh frequency `4 Ω` in rad/s.
    pub fn mesh_omega(&self) -> f64 {
        Self::TEETH as f64 * self.shaft_omega()
    }

    /// The load amplitude `L1 = M e (4Ω)²`.
    pub fn l1(&self) -> f64 {
        Self::INERTIA * Self::E * self.mesh_omega().powi(2)
    }

    /// The model (fundamental: [`TwoShaft::mesh_omega`]).
    pub fn model(&self) -> Result<Model> {
        self.model_with_contact_ratio(Self::CONTACT_RATIO)
    }

    /// The model with another contact ratio ε in [1, 2] (1.6: the stiffness jumps fall between
    /// the samples of every power-of-two N).
    pub fn model_with_contact_ratio(&self, contact_ratio: f64) -> Result<Model> {
        Model::builder(&["gear"])
            .mass_diagonal(&[Self::INERTIA])
            .element(
                "mesh",
                &[("gear", 1.0)],
                MeshStiffness::new(
                    1,
                    MeshProfile::Rectangular {
                        one_tooth: Self::ONE_TOOTH,
                        two_tooth: Self::TWO_TOOTH,
                        contact_ratio,
                    },
                    MeshDamping::Proportional(Self::BETA),
                ),
            )
            .load("gear", 0, Self::L0, 0.0)
            .load("gear", 1, self.l1(), 0.0)
            .build()
    }
}

/// The nondimensional gear pair with backlash and time-varying mesh stiffness
/// (Kahraman & Singh type), `x'' + 2ζ x' + (1 + ε cos Wt) g(x) = Fm + Fa cos Wt`, half backlash
/// b; fundamental W.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearBacklash {
    /// Damping ratio ζ.
    pub zeta: f64,
    /// Stiffness variation ε.
    pub eps: f64,
    /// Mean load Fm.
    pub fm: f64,
    /// Alternating load Fa.
    pub fa: f64,
    /// Half backlash b.
    pub b: f64,
}

impl Default for GearBacklash {
    /// ζ 0.05, ε 0.2, Fm 0.1, Fa 0.05, b 1 (parameter set A of the shared reference).
    fn default() -> Self {
        Self {
            zeta: 0.05,
            eps: 0.2,
            fm: 0.1,
            fa: 0.05,
            b: 1.0,
        }
    }
}

impl GearBacklash {
    /// The model.
    pub fn model(&self) -> Result<Model> {
        Model::builder(&["x"])
            .mass_diagonal(&[1.0])
            .damping(DMatrix::from_element(1, 1, 2.0 * self.zeta))
            .element(
                "contact",
                &[("x", 1.0)],
                Backlash::new(
                    self.b,
                    MeshProfile::Cosine {
                        mean: 1.0,
                        amplitude: self.eps,
                    },
                ),
            )
            .load("x", 0, self.fm, 0.0)
            .load("x", 1, self.fa, 0.0)
            .build()
    }
}

/// The Duffing oscillator `m x'' + c x' + k x + α x³ = F cos Wt`; fundamental W.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Duffing {
    /// Mass m.
    pub m: f64,
    /// Damping c.
    pub c: f64,
    /// Stiffness k.
    pub k: f64,
    /// Cubic coefficient α.
    pub alpha: f64,
    /// Forcing amplitude F.
    pub force: f64,
}

impl Default for Duffing {
    /// m 1, c 0.02, k 1, α 1, F 0.1 (the shared reference).
    fn default() -> Self {
        Self {
            m: 1.0,
            c: 0.02,
            k: 1.0,
            alpha: 1.0,
            force: 0.1,
        }
    }
}

impl Duffing {
    /// The model.
    pub fn model(&self) -> Result<Model> {
        Model::builder(&["x"])
            .mass_diagonal(&[self.m])
            .damping(DMatrix::from_element(1, 1, self.c))
            .element(
                "spring",
                &[("x", 1.0)],
                CubicSpring::new(self.k, self.alpha),
            )
            .load("x", 1, self.force, 0.0)
            .build()
    }
}
