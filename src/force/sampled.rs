//! A band-limited mesh-stiffness profile tabulated at the AFT's sample angles: a lookup where
//! the AFT evaluates it, the Fourier sum elsewhere.

use super::MeshProfile;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// A [`MeshProfile::Fourier`] tabulated at the shaft angles `θ_i = 2π i / N` of a mesh
/// `φ = z θ + φ0`: a lookup at those angles, the Fourier sum elsewhere.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledProfile {
    pub(super) fourier: MeshProfile,
    teeth: f64,
    phase: f64,
    pub(super) values: Vec<f64>,
}

impl SampledProfile {
    /// `profile` truncated to its orders `1..=orders` ([`MeshProfile::band_limited`]) and
    /// tabulated at the `samples` shaft angles of a mesh with `teeth` cycles per revolution and
    /// phase `phase`, by one inverse real FFT. Requires `orders · teeth < samples / 2`.
    pub fn new(
        profile: &MeshProfile,
        orders: usize,
        teeth: u32,
        phase: f64,
        samples: usize,
    ) -> Self {
        let fourier = profile.band_limited(orders);
        let z = teeth as usize;
        let top = (samples - 1) / 2;
        let mut x = vec![Complex64::default(); top + 1];
        if let MeshProfile::Fourier { mean, cos, sin } = &fourier {
            x[0] = Complex64::new(*mean, 0.0);
            for j in 1..=cos.len().max(sin.len()) {
                if j * z > top {
                    break;
                }
                let c = cos.get(j - 1).copied().unwrap_or(0.0);
                let s = sin.get(j - 1).copied().unwrap_or(0.0);
                x[j * z] += Complex64::new(c, -s) * Complex64::from_polar(1.0, j as f64 * phase);
            }
        } else {
            x[0] = Complex64::new(fourier.mean(), 0.0);
        }
        let mut values = vec![0.0; samples];
        if let Ok(basis) = crate::HarmonicBasis::new(1.0, top).and_then(|b| b.with_samples(samples))
        {
            let plan = crate::harmonic::AftPlan::new(basis);
            let mut scratch = plan.make_scratch();
            plan.synthesize_into(&x, |_| Complex64::new(1.0, 0.0), &mut values, &mut scratch);
        }
        Self {
            fourier,
            teeth: teeth as f64,
            phase,
            values,
        }
    }

    /// The table index of mesh angle `phi`, if it sits on a tabulated angle.
    #[inline]
    fn index(&self, phi: f64) -> Option<usize> {
        let n = self.values.len();
        let x = (phi - self.phase) / self.teeth * (n as f64 / TAU);
        let i = nearest(x);
        ((x - i).abs() <= 1e-7).then(|| (i as i64).rem_euclid(n as i64) as usize)
    }

    /// `out[j] = k` at `out.len()` consecutive tabulated angles from `first` to `last`, if they
    /// are (a copy of the table, wrapping at its end); `false` otherwise.
    pub(super) fn copy_run(&self, first: f64, last: f64, out: &mut [f64]) -> bool {
        let (n, len) = (self.values.len(), out.len());
        let (Some(a), Some(b)) = (self.index(first), self.index(last)) else {
            return false;
        };
        if len == 0 || len > n || (a + len - 1) % n != b {
            return false;
        }
        let head = len.min(n - a);
        out[..head].copy_from_slice(&self.values[a..a + head]);
        out[head..].copy_from_slice(&self.values[..len - head]);
        true
    }

    #[inline]
    pub(super) fn value(&self, phi: f64) -> f64 {
        let n = self.values.len();
        let x = (phi - self.phase) / self.teeth * (n as f64 / TAU);
        let i = nearest(x);
        if (x - i).abs() <= 1e-7 {
            self.values[(i as i64).rem_euclid(n as i64) as usize]
        } else {
            self.fourier.value(phi)
        }
    }
}

/// The integer nearest to `x` (ties away from zero) for `|x| < 2⁶²`, by conversions rather
/// than a libm `round` call (this sits in the contact-edge correction's law calls); NaN or
/// far out of range gives some value `(x - i).abs() > 1e-7` rejects.
#[inline]
fn nearest(x: f64) -> f64 {
    let shifted = if x >= 0.0 { x + 0.5 } else { x - 0.5 };
    (shifted as i64) as f64
}
