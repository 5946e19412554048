//! `backlash`: a dead-zone gear contact `f = k(φ) g(u) + c u̇ [|u| > b]`.

use super::profile::jump_angles;
use super::{ForceLaw, LinearPart, MeshProfile};
use crate::error::{check_finite, check_non_negative, Result};

/// Gear contact with backlash: `f = k(φ) g(u) + c u̇ [|u| > b]` with the dead zone
///
/// `g(u) = u - b` for `u > b`, `0` for `|u| <= b`, `u + b` for `u < -b`,
///
/// half backlash `b`, contact stiffness `k(φ)` (constant or a mesh profile over
/// `φ = z θ + φ0`), and contact damping `c` acting only in contact. The classic gear pair
/// `x'' + 2ζ x' + k(t) g(x) = F(t)` is one such element on a unit mass.
///
/// Its linear part is the engaged mesh on the chosen [`Flank`]: `f ≈ k̄ (u ∓ b) + c u̇` with
/// the mean contact stiffness `k̄` (offset `∓k̄ b`): the iteration is centred on the closed
/// contact, where a loaded gear pair runs.
///
/// ```
/// use hbal::force::{Backlash, ForceLaw, MeshProfile};
/// let contact = Backlash::new(1.0, MeshProfile::Cosine { mean: 1.0, amplitude: 0.2 });
/// assert_eq!(contact.force(0.0, 0.5, 3.0), 0.0);            // inside the backlash
/// assert!((contact.force(0.0, 1.5, 0.0) - 0.6).abs() < 1e-15); // (1 + 0.2)(1.5 - 1)
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Backlash {
    /// Half backlash b (>= 0).
    pub half_backlash: f64,
    /// Contact stiffness profile.
    pub stiffness: MeshProfile,
    /// Mesh cycles per fundamental period z (>= 1), default 1.
    #[serde(default = "one")]
    pub teeth: u32,
    /// Mesh phase φ0 in rad, default 0.
    #[serde(default)]
    pub phase: f64,
    /// Contact damping c (>= 0), acting only in contact; default 0.
    #[serde(default)]
    pub contact_damping: f64,
    /// The flank the iteration linearises about: `drive` (`u > b`, default) or `coast`
    /// (`u < -b`). Only the starting point and the paper's split depend on it.
    #[serde(default)]
    pub flank: Flank,
}

/// A gear flank of a backlash contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Flank {
    /// Drive flank, `u > b`.
    #[default]
    Drive,
    /// Coast flank, `u < -b`.
    Coast,
}

fn one() -> u32 {
    1
}

impl Backlash {
    /// A contact with half backlash `b` and stiffness profile `stiffness`, one mesh cycle per
    /// period, no contact damping.
    pub fn new(half_backlash: f64, stiffness: MeshProfile) -> Self {
        Self {
            half_backlash,
            stiffness,
            teeth: 1,
            phase: 0.0,
            contact_damping: 0.0,
            flank: Flank::Drive,
        }
    }

    /// Sets the contact damping c.
    pub fn with_contact_damping(mut self, c: f64) -> Self {
        self.contact_damping = c;
        self
    }

    /// Sets the number of mesh cycles per period z.
    pub fn with_teeth(mut self, teeth: u32) -> Self {
        self.teeth = teeth;
        self
    }
}

#[typetag::serde(name = "backlash")]
impl ForceLaw for Backlash {
    #[inline]
    fn force(&self, theta: f64, u: f64, du: f64) -> f64 {
        let b = self.half_backlash;
        let gap = if u > b {
            u - b
        } else if u < -b {
            u + b
        } else {
            return 0.0;
        };
        let k = self.stiffness.value(self.teeth as f64 * theta + self.phase);
        k * gap + self.contact_damping * du
    }
    fn force_batch(&self, theta: &[f64], u: &[f64], du: &[f64], out: &mut [f64]) {
        let mut k = [0.0; 64];
        let b = self.half_backlash;
        for (start, t) in (0..theta.len()).step_by(64).zip(theta.chunks(64)) {
            self.stiffness
                .values_into(self.teeth as f64, self.phase, t, &mut k);
            for (j, kj) in k[..t.len()].iter().enumerate() {
                let (x, v) = (u[start + j], du[start + j]);
                out[start + j] = if x > b {
                    kj * (x - b) + self.contact_damping * v
                } else if x < -b {
                    kj * (x + b) + self.contact_damping * v
                } else {
                    0.0
                };
            }
        }
    }
    fn derivatives_batch(
        &self,
        theta: &[f64],
        u: &[f64],
        _du: &[f64],
        dfdu: &mut [f64],
        dfddu: &mut [f64],
    ) {
        let mut k = [0.0; 64];
        for (start, t) in (0..theta.len()).step_by(64).zip(theta.chunks(64)) {
            self.stiffness
                .values_into(self.teeth as f64, self.phase, t, &mut k);
            for (j, kj) in k[..t.len()].iter().enumerate() {
                let engaged = u[start + j].abs() > self.half_backlash;
                dfdu[start + j] = if engaged { *kj } else { 0.0 };
                dfddu[start + j] = if engaged { self.contact_damping } else { 0.0 };
            }
        }
    }
    #[inline]
    fn derivatives(&self, theta: f64, u: f64, _du: f64) -> (f64, f64) {
        if u.abs() > self.half_backlash {
            let k = self.stiffness.value(self.teeth as f64 * theta + self.phase);
            (k, self.contact_damping)
        } else {
            (0.0, 0.0)
        }
    }
    fn linear_part(&self) -> LinearPart {
        let k = self.stiffness.mean();
        let offset = match self.flank {
            Flank::Drive => -k * self.half_backlash,
            Flank::Coast => k * self.half_backlash,
        };
        LinearPart {
            stiffness: k,
            damping: self.contact_damping,
            offset,
        }
    }
    fn state_names(&self) -> &'static [&'static str] {
        if self.half_backlash > 0.0 {
            &["coast", "open", "drive"]
        } else {
            &["coast", "drive"]
        }
    }
    fn kinks(&self) -> Vec<f64> {
        let b = self.half_backlash;
        if b > 0.0 {
            vec![-b, b]
        } else {
            vec![0.0]
        }
    }
    fn time_breakpoints(&self) -> Vec<f64> {
        jump_angles(&self.stiffness.jumps(), self.teeth, self.phase)
    }
    fn time_order(&self) -> Option<usize> {
        self.stiffness.time_order(self.teeth)
    }
    fn band_limited(&self, samples: usize, max_order: usize) -> Option<Box<dyn ForceLaw>> {
        let stiffness = self
            .stiffness
            .for_samples(self.teeth, self.phase, samples, max_order)?;
        Some(Box::new(Self {
            stiffness,
            ..self.clone()
        }))
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_non_negative(context, "half_backlash", self.half_backlash)?;
        super::profile::check_teeth(context, self.teeth)?;
        check_finite(context, "phase", self.phase)?;
        check_non_negative(context, "contact_damping", self.contact_damping)?;
        self.stiffness.validate(context)
    }
}
