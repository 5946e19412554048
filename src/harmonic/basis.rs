//! The truncated Fourier basis: excitation frequency Ω, period multiple ν (fundamental Ω/ν),
//! H harmonics, N time samples.

use crate::error::{in_magnitude_range, Error, Result};
use std::f64::consts::TAU;

/// Excitation angular frequency Ω, number of harmonics H and time samples N; the period
/// multiple ν (1 by default) sets the fundamental Ω/ν and the period νT.
///
/// A basis with ν = 2 represents the period-2 orbits born at a period doubling: the Fourier
/// series runs over `(Ω/2) t`, the force laws still see the shaft angle `θ = Ω t`, and a load of
/// order k sits at harmonic `2k`.
///
/// The default N is the smallest power of two `>= 4H + 1`: a cubic force is then free of
/// aliasing in the kept harmonics, the FFT is fastest, and the jumps of a rectangular mesh
/// stiffness with a simple contact ratio fall on samples (see [`crate::force::ForceLaw::time_breakpoints`]).
///
/// ```
/// use hbal::HarmonicBasis;
/// let b = HarmonicBasis::new(100.0, 32).unwrap();
/// assert_eq!(b.samples(), 256);
/// assert!(HarmonicBasis::new(100.0, 32).unwrap().with_samples(60).is_err()); // N < 2H+1
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HarmonicBasis {
    omega: f64,
    harmonics: usize,
    samples: usize,
    #[serde(default = "one")]
    subharmonic: usize,
    /// Whether the harmonic balance corrects the coupling through the harmonics above H of
    /// laws whose force jumps in time (see [`HarmonicBasis::with_tail_correction`]); `None`:
    /// the default, off at a fixed H, on for automatic harmonics.
    #[serde(default)]
    tail: Option<bool>,
}

fn one() -> usize {
    1
}

impl HarmonicBasis {
    /// Largest accepted H (65 536; the dense Jacobian of Newton and Broyden has a lower limit,
    /// see [`crate::solve::Newton`]).
    pub const MAX_HARMONICS: usize = 1 << 16;

    /// Largest period multiple ν.
    pub const MAX_SUBHARMONIC: usize = 64;

    /// Ω in rad/s (finite, > 0, in [[`MIN_MAGNITUDE`], [`MAX_MAGNITUDE`]], so that the period
    /// and `(kΩ)²` are finite) and H harmonics (0 = static only, at most
    /// [`HarmonicBasis::MAX_HARMONICS`]); N by default.
    ///
    /// [`MIN_MAGNITUDE`]: crate::error::MIN_MAGNITUDE
    /// [`MAX_MAGNITUDE`]: crate::error::MAX_MAGNITUDE
    pub fn new(omega: f64, harmonics: usize) -> Result<Self> {
        check_omega(omega)?;
        if harmonics > Self::MAX_HARMONICS {
            return Err(Error::invalid(
                "harmonic basis",
                "harmonics",
                harmonics as f64,
                format!("<= {}", Self::MAX_HARMONICS),
            ));
        }
        let samples = (4 * harmonics + 1).next_power_of_two().max(8);
        Ok(Self {
            omega,
            harmonics,
            samples,
            subharmonic: 1,
            tail: None,
        })
    }

    /// The same basis at another Ω (H, N and ν kept).
    pub fn with_omega(mut self, omega: f64) -> Result<Self> {
        check_omega(omega)?;
        self.omega = omega;
        Ok(self)
    }

    /// The same basis with period multiple `nu` (1 ..= [`HarmonicBasis::MAX_SUBHARMONIC`]):
    /// fundamental Ω/ν.
    pub fn with_subharmonic(mut self, nu: usize) -> Result<Self> {
        if !(1..=Self::MAX_SUBHARMONIC).contains(&nu) {
            return Err(Error::invalid(
                "harmonic basis",
                "period multiple",
                nu as f64,
                format!("in 1..={}", Self::MAX_SUBHARMONIC),
            ));
        }
        self.subharmonic = nu;
        Ok(self)
    }

    /// The basis of the period-doubled orbits: ν, H and N doubled, so that the harmonics of
    /// this basis are the even harmonics of the new one, resolved as finely.
    ///
    /// ```
    /// use hbal::HarmonicBasis;
    /// let b = HarmonicBasis::new(2.0, 32).unwrap().doubled().unwrap();
    /// assert_eq!((b.subharmonic(), b.harmonics(), b.samples()), (2, 64, 512));
    /// assert_eq!(b.fundamental(), 1.0);
    /// ```
    pub fn doubled(self) -> Result<Self> {
        if self.subharmonic >= Self::MAX_SUBHARMONIC {
            return Err(Error::invalid(
                "harmonic basis",
                "period multiple",
                (2 * self.subharmonic) as f64,
                format!("<= {}", Self::MAX_SUBHARMONIC),
            ));
        }
        let b = Self::new(self.omega, 2 * self.harmonics)?.with_samples(2 * self.samples)?;
        Ok(Self {
            subharmonic: 2 * self.subharmonic,
            tail: self.tail,
            ..b
        })
    }

    /// Sets N (at least 2H+1; prefer small prime factors).
    pub fn with_samples(mut self, samples: usize) -> Result<Self> {
        if samples < 2 * self.harmonics + 1 || !(2..=64 * Self::MAX_HARMONICS).contains(&samples) {
            return Err(Error::TooFewSamples {
                harmonics: self.harmonics,
                samples,
            });
        }
        self.samples = samples;
        Ok(self)
    }

    /// The same basis with the tail correction on or off. By default it is off at a fixed H
    /// (the plain Galerkin truncation, what other harmonic-balance tools compute) and on for
    /// automatic harmonics ([`crate::solve::solve_auto`]), which reach a tolerance at a lower
    /// H with it.
    ///
    /// Where a force law linear in the state has a coefficient that jumps in time (a
    /// rectangular mesh stiffness), the exact solution's harmonics above H decay only like
    /// `l⁻³` and, through the jumps, still feed the kept ones: a plain truncation is good to
    /// O(H⁻³). The correction adds that feedback, from the Schur complement of the harmonics
    /// `H < l ≤ L` with their dynamic stiffness taken as diagonal and its receptance
    /// `G_l ≈ −C/(lΩ)² + B/(lΩ)⁴` between the jumping elements (`C = Wᵀ M⁻¹ W`, `B` so that
    /// `G_H` is exact), see `residual::tail`. It switches itself off where the harmonics above
    /// H are not mass-dominated. Its price: four FFTs of 10H–20H samples per residual
    /// evaluation and jumping element (six where the damping varies otherwise than with the stiffness),
    /// and, as it is not in the Jacobian, a few more Newton steps.
    ///
    /// ```
    /// use hbal::HarmonicBasis;
    /// let b = HarmonicBasis::new(100.0, 32).unwrap();
    /// assert!(!b.tail_correction());
    /// assert_eq!(b.tail_correction_setting(), None);
    /// assert!(b.with_tail_correction(true).tail_correction());
    /// ```
    pub fn with_tail_correction(mut self, on: bool) -> Self {
        self.tail = Some(on);
        self
    }

    /// Whether the tail correction is on at this fixed H ([`HarmonicBasis::with_tail_correction`]).
    pub fn tail_correction(&self) -> bool {
        self.tail.unwrap_or(false)
    }

    /// The tail correction as set: `None` where it was left to the default (off at a fixed H,
    /// on for automatic harmonics).
    pub fn tail_correction_setting(&self) -> Option<bool> {
        self.tail
    }

    /// The same basis with the tail correction set as in `other` (also left to the default).
    pub fn with_tail_correction_of(mut self, other: &HarmonicBasis) -> Self {
        self.tail = other.tail;
        self
    }

    /// Ω in rad/s: the excitation (shaft) frequency, the swept parameter.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The period multiple ν (1 for orbits with the excitation's period).
    pub fn subharmonic(&self) -> usize {
        self.subharmonic
    }

    /// The fundamental Ω/ν of the Fourier series in rad/s: harmonic k oscillates at kΩ/ν.
    pub fn fundamental(&self) -> f64 {
        self.omega / self.subharmonic as f64
    }

    /// H.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }

    /// N.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Period νT = 2πν/Ω of the orbits in s.
    pub fn period(&self) -> f64 {
        TAU / self.fundamental()
    }

    /// Angle θ_j = 2π j / N of sample j, on the fundamental ((Ω/ν) t).
    #[inline]
    pub fn theta(&self, j: usize) -> f64 {
        TAU * j as f64 / self.samples as f64
    }

    /// The shaft angle `Ω t` at sample j, reduced to [0, 2π): what force laws see.
    #[inline]
    pub fn shaft_angle(&self, j: usize) -> f64 {
        TAU * ((j * self.subharmonic) % self.samples) as f64 / self.samples as f64
    }
}

/// Ω must be finite, positive and in the magnitude range of scene numbers.
fn check_omega(omega: f64) -> Result<()> {
    if omega > 0.0 && in_magnitude_range(omega) {
        Ok(())
    } else {
        Err(Error::invalid(
            "harmonic basis",
            "omega",
            omega,
            format!(
                "finite and in [{:e}, {:e}] rad/s",
                crate::error::MIN_MAGNITUDE,
                crate::error::MAX_MAGNITUDE
            ),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::HarmonicBasis;

    /// The tail correction's setting in files: missing or `null` is the default (`None`),
    /// `true`/`false` as set (files from before the default changed keep their `true`).
    #[test]
    fn tail_setting_reads_back() {
        let b = HarmonicBasis::new(3.0, 8).unwrap();
        let text = serde_json::to_string(&b).unwrap();
        let back: HarmonicBasis = serde_json::from_str(&text).unwrap();
        assert_eq!(back.tail_correction_setting(), None);
        let on = serde_json::to_string(&b.with_tail_correction(true)).unwrap();
        let back: HarmonicBasis = serde_json::from_str(&on).unwrap();
        assert_eq!(back.tail_correction_setting(), Some(true));
        let old = r#"{"omega":3.0,"harmonics":8,"samples":64,"tail":true}"#;
        let back: HarmonicBasis = serde_json::from_str(old).unwrap();
        assert!(back.tail_correction() && back.subharmonic() == 1);
        let missing = r#"{"omega":3.0,"harmonics":8,"samples":64}"#;
        let back: HarmonicBasis = serde_json::from_str(missing).unwrap();
        assert_eq!(back.tail_correction_setting(), None);
        assert!(!back.tail_correction());
        // Copied as set, also when left to the default.
        let other = HarmonicBasis::new(5.0, 16).unwrap();
        assert_eq!(
            other.with_tail_correction_of(&b).tail_correction_setting(),
            None
        );
        let set = b.with_tail_correction(false);
        assert_eq!(
            other
                .with_tail_correction_of(&set)
                .tail_correction_setting(),
            Some(false)
        );
    }
}
