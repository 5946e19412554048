//! Periodic mesh-stiffness and mesh-damping profiles over the mesh angle `φ = z θ + φ0`.

use super::sampled::SampledProfile;
use crate::error::{check_finite, check_non_negative, Error, Result};
use std::f64::consts::TAU;
use std::sync::Arc;

/// Largest number of mesh cycles per fundamental period (`teeth` of a mesh law, the mesh order
/// of a gear stage): [`HarmonicBasis::MAX_HARMONICS`](crate::HarmonicBasis::MAX_HARMONICS), the
/// highest order any harmonic basis resolves. It also bounds the work of the time-domain
/// integrators, which stop at every stiffness jump (two per mesh cycle).
pub const MAX_TEETH: u32 = crate::HarmonicBasis::MAX_HARMONICS as u32;

/// Checks a mesh law's `teeth`: an integer in `1..=MAX_TEETH`.
pub(crate) fn check_teeth(context: &str, teeth: u32) -> Result<()> {
    if (1..=MAX_TEETH).contains(&teeth) {
        Ok(())
    } else {
        Err(Error::invalid(
            context,
            "teeth",
            teeth as f64,
            format!(
                "an integer in 1..={MAX_TEETH}: mesh cycles per period of the fundamental, \
                 and more is more than any harmonic basis holds (make the mesh order the \
                 fundamental with `fundamental.order`)"
            ),
        ))
    }
}

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
    /// A band-limited profile tabulated at the AFT's sample angles (built by
    /// [`ForceLaw::band_limited`](super::ForceLaw::band_limited) for one harmonic basis; not
    /// in scene files).
    #[serde(skip)]
    Sampled(Arc<SampledProfile>),
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
                // e^{i (j+1) φ} by rotation: one sine and cosine however many orders.
                let (s1, c1) = phi.sin_cos();
                let (mut re, mut im) = (c1, s1);
                let mut k = *mean;
                for j in 0..cos.len().max(sin.len()) {
                    k += cos.get(j).map_or(0.0, |c| c * re) + sin.get(j).map_or(0.0, |s| s * im);
                    (re, im) = (re * c1 - im * s1, re * s1 + im * c1);
                }
                k
            }
            MeshProfile::Sampled(table) => table.value(phi),
        }
    }

    /// `out[j] = k(z θ[j] + φ0)` for a block of at most 64 angles. For equidistant angles the
    /// cosine profile is evaluated by the angle-addition recurrence from one `cos`/`sin` pair
    /// per block (error ~1e-15 per step), instead of one `cos` per sample.
    pub fn values_into(&self, z: f64, phase: f64, theta: &[f64], out: &mut [f64]) {
        debug_assert!(theta.len() <= 64 && out.len() >= theta.len());
        let n = theta.len();
        if let MeshProfile::Sampled(table) = self {
            // The AFT's own consecutive samples: one lookup, then a copy.
            if table.copy_run(
                z * theta[0] + phase,
                z * theta[n - 1] + phase,
                &mut out[..n],
            ) {
                return;
            }
        }
        if let (MeshProfile::Cosine { mean, amplitude }, true) = (self, n > 2) {
            let step = theta[1] - theta[0];
            // Rising angles whose ends agree with a uniform step (the AFT's own samples; the
            // torus passes each base's angles line by line, so never repeated angles).
            let uniform = step > 0.0
                && (theta[n - 1] - theta[0] - (n - 1) as f64 * step).abs()
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
            MeshProfile::Sampled(table) => table.fourier.mean(),
        }
    }

    /// The profile truncated to its Fourier orders `1..=orders` (exact coefficients), as a
    /// [`MeshProfile::Fourier`]; a constant or cosine profile is returned as it is (already
    /// band-limited), `orders = 0` gives the mean.
    ///
    /// Evaluated at the samples, the truncated profile makes the AFT of `k(φ) u` the exact
    /// Galerkin projection onto the kept harmonics when the product's orders stay below the
    /// aliasing limit (see [`crate::HarmonicBalance`]), whereas sampling a jump costs O(1/N).
    ///
    /// The rectangular profile is `k1 + (k2 - k1) 1[0, a)(φ)` per cycle with `a = 2π(ε - 1)`,
    /// so `cos[j-1] = (k2 - k1) sin(j a) / (j π)` and `sin[j-1] = (k2 - k1) (1 - cos(j a)) / (j π)`.
    ///
    /// ```
    /// use hbal::force::MeshProfile;
    /// let rect = MeshProfile::Rectangular { one_tooth: 1.0, two_tooth: 2.0, contact_ratio: 1.5 };
    /// let smooth = rect.band_limited(2000);
    /// assert!((smooth.mean() - 1.5).abs() < 1e-15);
    /// assert!((smooth.value(0.75 * std::f64::consts::TAU) - 1.0).abs() < 1e-3); // one tooth
    /// assert!((smooth.value(1.0) - 2.0).abs() < 1e-3);                         // two teeth
    /// ```
    pub fn band_limited(&self, orders: usize) -> MeshProfile {
        match self {
            MeshProfile::Rectangular {
                one_tooth,
                two_tooth,
                contact_ratio,
            } => {
                let a = TAU * (contact_ratio - 1.0);
                let dk = two_tooth - one_tooth;
                let c = (1..=orders)
                    .map(|j| dk * (j as f64 * a).sin() / (j as f64 * std::f64::consts::PI))
                    .collect();
                let s = (1..=orders)
                    .map(|j| dk * (1.0 - (j as f64 * a).cos()) / (j as f64 * std::f64::consts::PI))
                    .collect();
                MeshProfile::Fourier {
                    mean: self.mean(),
                    cos: c,
                    sin: s,
                }
            }
            MeshProfile::Fourier { mean, cos, sin } => MeshProfile::Fourier {
                mean: *mean,
                cos: cos.iter().take(orders).copied().collect(),
                sin: sin.iter().take(orders).copied().collect(),
            },
            MeshProfile::Cosine { mean, .. } if orders == 0 => {
                MeshProfile::Constant { stiffness: *mean }
            }
            MeshProfile::Sampled(table) => table.fourier.band_limited(orders),
            other => other.clone(),
        }
    }

    /// The order at which a mesh of `teeth` cycles per period with this profile varies in
    /// time ([`ForceLaw::time_order`](super::ForceLaw::time_order)): `teeth`, or `None` for a
    /// profile that does not vary.
    pub fn time_order(&self, teeth: u32) -> Option<usize> {
        let constant = matches!(self, MeshProfile::Constant { .. })
            || matches!(self, MeshProfile::Cosine { amplitude, .. } if *amplitude == 0.0);
        (!constant).then_some(teeth as usize)
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
                check_finite(context, "amplitude", *amplitude)?;
                if amplitude.abs() > *mean {
                    return Err(Error::invalid(
                        context,
                        "amplitude",
                        *amplitude,
                        format!(
                            "at most the mean {mean} in magnitude (the stiffness falls to mean - \
                             |amplitude|, and a mesh stiffness must not be negative)"
                        ),
                    ));
                }
                Ok(())
            }
            MeshProfile::Fourier { mean, cos, sin } => {
                check_non_negative(context, "mean", *mean)?;
                for (j, c) in cos.iter().enumerate() {
                    check_finite(context, &format!("cos[{j}]"), *c)?;
                }
                for (j, s) in sin.iter().enumerate() {
                    check_finite(context, &format!("sin[{j}]"), *s)?;
                }
                let orders = cos.len().max(sin.len());
                if orders > MAX_TEETH as usize {
                    return Err(Error::InvalidElement {
                        context: context.into(),
                        reason: format!(
                            "the Fourier profile has {orders} orders, more than any harmonic \
                             basis resolves ({MAX_TEETH})"
                        ),
                    });
                }
                let (lowest, phi) = self.fourier_minimum(orders);
                let scale = mean + cos.iter().chain(sin).map(|c| c.abs()).sum::<f64>();
                if lowest < -1e-9 * scale {
                    return Err(Error::InvalidElement {
                        context: context.into(),
                        reason: format!(
                            "the Fourier stiffness profile falls to {lowest:.6e} at φ = {phi:.4} \
                             rad: a mesh stiffness must not be negative (raise `mean` or lower \
                             the coefficients)"
                        ),
                    });
                }
                Ok(())
            }
            MeshProfile::Sampled(_) => Ok(()),
        }
    }

    /// The lowest value of a Fourier profile with `orders` orders on a grid of at least 16
    /// points per period of its highest order (one inverse FFT), and its angle.
    fn fourier_minimum(&self, orders: usize) -> (f64, f64) {
        if orders == 0 {
            return (self.mean(), 0.0);
        }
        let samples = (16 * orders).next_power_of_two();
        let table = SampledProfile::new(self, orders, 1, 0.0, samples);
        let (i, lowest) =
            table
                .values
                .iter()
                .copied()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |a, (i, v)| if v < a.1 { (i, v) } else { a },
                );
        (lowest, TAU * i as f64 / samples as f64)
    }

    /// The profile a harmonic basis with `samples` shaft angles per revolution should evaluate
    /// instead of this one, keeping the orders of `θ` up to `max_order` (see
    /// [`ForceLaw::band_limited`](super::ForceLaw::band_limited)): `None` where sampling the
    /// profile itself is exact (constant, cosine, a Fourier series within the limit).
    pub fn for_samples(
        &self,
        teeth: u32,
        phase: f64,
        samples: usize,
        max_order: usize,
    ) -> Option<MeshProfile> {
        let orders = max_order / teeth.max(1) as usize;
        let needed = match self {
            MeshProfile::Rectangular { .. } => !self.jumps().is_empty(),
            MeshProfile::Fourier { cos, sin, .. } => cos.len().max(sin.len()) > orders,
            _ => false,
        };
        needed.then(|| {
            MeshProfile::Sampled(Arc::new(SampledProfile::new(
                self, orders, teeth, phase, samples,
            )))
        })
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
