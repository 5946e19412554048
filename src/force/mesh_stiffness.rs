//! `mesh_stiffness`: a periodically varying gear-mesh stiffness and damping,
//! `f = k(φ) u + d(φ) u̇` with mesh angle `φ = z θ + φ0`.

use super::profile::{cycle_fraction, jump_angles};
use super::{ForceLaw, LinearPart, MeshDamping, MeshProfile};
use crate::error::{check_finite, Result};

/// Time-varying gear-mesh stiffness `f = k(φ) u + d(φ) u̇`, `φ = z θ + φ0`.
///
/// The paper's two-shaft model (section 4) is one such element with a rectangular profile,
/// `z = 4` mesh cycles per shaft revolution and `d = β k`.
///
/// ```
/// use hbal::force::{ForceLaw, MeshDamping, MeshProfile, MeshStiffness};
/// let mesh = MeshStiffness::new(
///     4,
///     MeshProfile::Rectangular { one_tooth: 2.5e5, two_tooth: 5e5, contact_ratio: 1.5 },
///     MeshDamping::Proportional(1e-5),
/// );
/// assert_eq!(mesh.linear_part().stiffness, 3.75e5);
/// // Two-tooth contact at the start of each mesh cycle, one-tooth in its second half:
/// assert_eq!(mesh.force(0.1, 1.0, 0.0), 5e5);
/// assert_eq!(mesh.force(1.0, 1.0, 0.0), 2.5e5);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshStiffness {
    /// Mesh cycles per fundamental period z (>= 1).
    pub teeth: u32,
    /// Mesh phase φ0 in rad, default 0.
    #[serde(default)]
    pub phase: f64,
    /// Stiffness profile.
    pub profile: MeshProfile,
    /// Damping, default none.
    #[serde(default)]
    pub damping: MeshDamping,
}

impl MeshStiffness {
    /// A mesh with `teeth` cycles per period, phase 0.
    pub fn new(teeth: u32, profile: MeshProfile, damping: MeshDamping) -> Self {
        Self {
            teeth,
            phase: 0.0,
            profile,
            damping,
        }
    }

    /// Sets the mesh phase φ0 (rad).
    pub fn with_phase(mut self, phase: f64) -> Self {
        self.phase = phase;
        self
    }

    #[inline]
    fn stiffness_at(&self, theta: f64) -> f64 {
        self.profile.value(self.teeth as f64 * theta + self.phase)
    }
}

#[typetag::serde(name = "mesh_stiffness")]
impl ForceLaw for MeshStiffness {
    #[inline]
    fn force(&self, theta: f64, u: f64, du: f64) -> f64 {
        let k = self.stiffness_at(theta);
        k * u + self.damping.value(k) * du
    }
    fn force_batch(&self, theta: &[f64], u: &[f64], du: &[f64], out: &mut [f64]) {
        let z = self.teeth as f64;
        let samples = out.iter_mut().zip(theta).zip(u).zip(du);
        match (&self.profile, self.damping) {
            (
                MeshProfile::Rectangular {
                    one_tooth,
                    two_tooth,
                    contact_ratio,
                },
                damping,
            ) => {
                let two = (*two_tooth, damping.value(*two_tooth));
                let one = (*one_tooth, damping.value(*one_tooth));
                let edge = contact_ratio - 1.0;
                for (((o, &t), &x), &v) in samples {
                    let (k, d) = if cycle_fraction(z * t + self.phase) < edge {
                        two
                    } else {
                        one
                    };
                    *o = k * x + d * v;
                }
            }
            (profile, damping) => {
                let _ = samples;
                let mut k = [0.0; 64];
                for (start, t) in (0..theta.len()).step_by(64).zip(theta.chunks(64)) {
                    profile.values_into(z, self.phase, t, &mut k);
                    for (j, kj) in k[..t.len()].iter().enumerate() {
                        out[start + j] = kj * u[start + j] + damping.value(*kj) * du[start + j];
                    }
                }
            }
        }
    }
    #[inline]
    fn derivatives(&self, theta: f64, _u: f64, _du: f64) -> (f64, f64) {
        let k = self.stiffness_at(theta);
        (k, self.damping.value(k))
    }
    fn linear_part(&self) -> LinearPart {
        let k = self.profile.mean();
        LinearPart {
            stiffness: k,
            damping: self.damping.value(k),
            offset: 0.0,
        }
    }
    fn time_breakpoints(&self) -> Vec<f64> {
        jump_angles(&self.profile.jumps(), self.teeth, self.phase)
    }
    fn time_order(&self) -> Option<usize> {
        self.profile.time_order(self.teeth)
    }
    fn is_linear_in_state(&self) -> bool {
        true
    }
    fn is_piecewise_constant(&self) -> bool {
        matches!(
            self.profile,
            MeshProfile::Rectangular { .. } | MeshProfile::Constant { .. }
        )
    }
    fn band_limited(&self, samples: usize, max_order: usize) -> Option<Box<dyn ForceLaw>> {
        let profile = self
            .profile
            .for_samples(self.teeth, self.phase, samples, max_order)?;
        Some(Box::new(Self {
            profile,
            ..self.clone()
        }))
    }
    fn validate(&self, context: &str) -> Result<()> {
        super::profile::check_teeth(context, self.teeth)?;
        check_finite(context, "phase", self.phase)?;
        self.profile.validate(context)?;
        self.damping.validate(context)
    }
}
