//! The truncated Fourier basis: fundamental Ω, H harmonics, N time samples.

use crate::error::{check_positive, Error, Result};
use std::f64::consts::TAU;

/// Fundamental angular frequency Ω, number of harmonics H and time samples N.
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
}

impl HarmonicBasis {
    /// Largest accepted H (65 536; the dense Jacobian of Newton and Broyden has a lower limit,
    /// see [`crate::solve::Newton`]).
    pub const MAX_HARMONICS: usize = 1 << 16;

    /// Ω in rad/s (finite, > 0) and H harmonics (0 = static only, at most
    /// [`HarmonicBasis::MAX_HARMONICS`]); N by default.
    pub fn new(omega: f64, harmonics: usize) -> Result<Self> {
        check_positive("harmonic basis", "omega", omega)?;
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

    /// Ω in rad/s.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// H.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }

    /// N.
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// Period T = 2π/Ω in s.
    pub fn period(&self) -> f64 {
        TAU / self.omega
    }

    /// Angle θ_j = 2π j / N of sample j.
    #[inline]
    pub fn theta(&self, j: usize) -> f64 {
        TAU * j as f64 / self.samples as f64
    }
}
