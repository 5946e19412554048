//! Periodic mesh-stiffness and mesh-damping profiles over the mesh angle `φ = z θ + φ0`.

use crate::error::{check_finite, check_non_negative, Error, Result};
use std::f64::consts::TAU;

/// Stiffness `k(φ)` over one mesh cycle, `φ = z θ + φ0` (`z` mesh cycles per fundamental period,
/// `φ0` the phase in rad). Scene files name the shape in the field `shape`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum MeshProfile {
    /// A constant stiffness.
    Constant {
        /// k (>= 0).
        stiffness: f64,
    },
    /// One-/two-tooth contact alternation: with `m = frac(φ / 2π)`, two teeth are in contact
    /// (`two_tooth`) while `m < ε - 1` and one tooth (`one_tooth`) otherwise, where `ε ∈ [1, 2]`
    /// is the contact ratio. Mean: `(ε-1) k2 + (2-ε) k1`.
    Rectangular {
        /// One-tooth stiffness k1 (>= 0).
        one_tooth: f64,
        /// Two-tooth stiffness k2 (>= 0).
        two_tooth: f64,
        /// Contact ratio ε in [1, 2].
        contact_ratio: f64,
    },
    /// `k(φ) = mean + amplitude cos φ`.
    Cosine {
        /// Mean stiffness (>= 0).
        mean: f64,
        /// Amplitude (finite).
        amplitude: f64,
    },
    /// `k(φ) = mean + Σ_j cos[j-1] cos(jφ) + sin[j-1] sin(jφ)`, j = 1, 2, ...
    Fourier {
        /// Mean stiffness (>= 0).
        mean: f64,
        /// Cosine coefficients of orders 1, 2, ...
        #[serde(default)]
        cos: Vec<f64>,
        /// Sine coefficients of orders 1, 2, ...
        #[serde(default)]
        sin: Vec<f64>,
    },
}

impl MeshProfile {
    /// The stiffness at mesh angle `phi` (rad).
    #[inline]
    pub fn value(&self, phi: f64) -> f64 {
        match self {
            MeshProfile::Constant { stiffness } => *stiffness,
            MeshProfile::Rectangular {
                one_tooth,
                two_tooth,
                contact_ratio,
            } => {
                if cycle_fraction(phi) < contact_ratio - 1.0 {
                    *two_tooth
                } else {
                    *one_tooth
                }
            }
            MeshProfile::Cosine { mean, amplitude } => mean + amplitude * phi.cos(),
            MeshProfile::Fourier { mean, cos, sin } => {
                let mut k = *mean;
                for (j, c) in cos.iter().enumerate() {
                    k += c * ((j + 1) as f64 * phi).cos();
                }
                for (j, s) in sin.iter().enumerate() {
                    k += s * ((j + 1) as f64 * phi).sin();
                }
                k
            }
        }
    }

    /// `out[j] = k(z θ[j] + φ0)` for a block of at most 64 angles. For equidistant angles the
    /// cosine profile is evaluated by the angle-addition recurrence from one `cos`/`sin` pair
    /// per block (error ~1e-15 per step), instead of one `cos` per sample.
    pub fn values_into(&self, z: f64, phase: f64, theta: &[f64], out: &mut [f64]) {
        debug_assert!(theta.len() <= 64 && out.len() >= theta.len());
        let n = theta.len();
        if let (MeshProfile::Cosine { mean, amplitude }, true) = (self, n > 2) {
            let step = theta[1] - theta[0];
            let uniform = (theta[n - 1] - theta[0] - (n - 1) as f64 * step).abs()
                <= 1e-12 * theta[n - 1].abs().max(1.0);
            if uniform {
                let (s0, c0) = (z * theta[0] + phase).sin_cos();
                let (sd, cd) = (z * step).sin_cos();
                let (mut c, mut s) = (c0, s0);
                for o in out[..n].iter_mut() {
                    *o = mean + amplitude * c;
                    (c, s) = (c * cd - s * sd, s * cd + c * sd);
                }
                return;
            }
        }
        for (o, t) in out[..n].iter_mut().zip(theta) {
            *o = self.value(z * t + phase);
        }
    }

    /// The mean stiffness over one mesh cycle (exact).
    pub fn mean(&self) -> f64 {
        match self {
            MeshProfile::Constant { stiffness } => *stiffness,
            MeshProfile::Rectangular {
                one_tooth,
                two_tooth,
                contact_ratio,
            } => (contact_ratio - 1.0) * two_tooth + (2.0 - contact_ratio) * one_tooth,
            MeshProfile::Cosine { mean, .. } | MeshProfile::Fourier { mean, .. } => *mean,
        }
    }

    /// Fractions `m ∈ [0, 1)` of the mesh cycle where the stiffness jumps.
    pub fn jumps(&self) -> Vec<f64> {
        match self {
            MeshProfile::Rectangular {
                one_tooth,
                two_tooth,
                contact_ratio,
            } if one_tooth != two_tooth && *contact_ratio > 1.0 && *contact_ratio < 2.0 => {
                vec![0.0, contact_ratio - 1.0]
            }
            _ => Vec::new(),
        }
    }

    /// Checks the parameters.
    pub fn validate(&self, context: &str) -> Result<()> {
        match self {
            MeshProfile::Constant { stiffness } => {
                check_non_negative(context, "stiffness", *stiffness)
            }
            MeshProfile::Rectangular {
                one_tooth,
                two_tooth,
                contact_ratio,
            } => {
                check_non_negative(context, "one_tooth", *one_tooth)?;
                check_non_negative(context, "two_tooth", *two_tooth)?;
                if !(contact_ratio.is_finite() && (1.0..=2.0).contains(contact_ratio)) {
                    return Err(Error::invalid(
                        context,
                        "contact_ratio",
                        *contact_ratio,
                        "in [1, 2] (one- to two-tooth contact)",
                    ));
                }
                Ok(())
            }
            MeshProfile::Cosine { mean, amplitude } => {
                check_non_negative(context, "mean", *mean)?;
                check_finite(context, "amplitude", *amplitude)
            }
            MeshProfile::Fourier { mean, cos, sin } => {
                check_non_negative(context, "mean", *mean)?;
                for (j, c) in cos.iter().enumerate() {
                    check_finite(context, &format!("cos[{j}]"), *c)?;
                }
                for (j, s) in sin.iter().enumerate() {
                    check_finite(context, &format!("sin[{j}]"), *s)?;
                }
                Ok(())
            }
        }
    }
}

/// `frac(φ / 2π)` in [0, 1), without a libm `floor` call (this sits in the AFT hot loop).
#[inline]
pub(crate) fn cycle_fraction(phi: f64) -> f64 {
    let x = phi * (1.0 / TAU);
    let m = x - (x as i64) as f64;
    if m < 0.0 {
        m + 1.0
    } else {
        m
    }
}

/// Mesh damping: constant, or proportional to the mesh stiffness (`d(φ) = β k(φ)`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum MeshDamping {
    /// `d = c` (>= 0).
    Constant(f64),
    /// `d(φ) = β k(φ)`, β in seconds (>= 0).
    Proportional(f64),
}

impl Default for MeshDamping {
    fn default() -> Self {
        MeshDamping::Constant(0.0)
    }
}

impl MeshDamping {
    /// The damping for stiffness `k`.
    #[inline]
    pub fn value(&self, k: f64) -> f64 {
        match self {
            MeshDamping::Constant(c) => *c,
            MeshDamping::Proportional(beta) => beta * k,
        }
    }

    /// Checks the parameter.
    pub fn validate(&self, context: &str) -> Result<()> {
        match self {
            MeshDamping::Constant(c) => check_non_negative(context, "damping.constant", *c),
            MeshDamping::Proportional(b) => check_non_negative(context, "damping.proportional", *b),
        }
    }
}

/// Maps cycle fractions of `jumps` to fundamental angles θ ∈ [0, 2π) for `teeth` cycles per
/// period and mesh phase `phase` (rad): `z θ + φ0 = 2π (j + m)`.
pub(crate) fn jump_angles(jumps: &[f64], teeth: u32, phase: f64) -> Vec<f64> {
    let z = teeth as f64;
    let mut out = Vec::with_capacity(jumps.len() * teeth as usize);
    for j in 0..teeth {
        for m in jumps {
            out.push(((TAU * (j as f64 + m) - phase) / z).rem_euclid(TAU));
        }
    }
    out.sort_by(f64::total_cmp);
    out
}
