//! External load harmonics.

use super::SpeedLaw;
use std::sync::Arc;

/// One load harmonic on one DOF: `f_dof(t) += c(Ω) · cos(k Ω t) + s(Ω) · sin(k Ω t)`.
///
/// Constant over speed, `(c, s) = (cos, sin)`; with a [`SpeedLaw`] `T`,
/// `c + i s = (cos + i sin) · T(Ω)` ([`Load::at`]). Order `k = 0` is a static load (its `sin`
/// is 0).
#[derive(Debug, Clone, PartialEq)]
pub struct Load {
    /// DOF index.
    pub dof: usize,
    /// Harmonic order k of the fundamental.
    pub order: usize,
    /// Cosine amplitude (of the base phasor where the load follows the speed).
    pub cos: f64,
    /// Sine amplitude (of the base phasor where the load follows the speed).
    pub sin: f64,
    /// How the load follows the speed, if it does.
    pub speed: Option<Arc<SpeedLaw>>,
}

impl Load {
    /// `(c, s)` at the reference speed Ω (rad/s).
    pub fn at(&self, omega: f64) -> (f64, f64) {
        match &self.speed {
            None => (self.cos, self.sin),
            Some(law) => {
                let z = num_complex::Complex64::new(self.cos, self.sin) * law.factor(omega);
                (z.re, z.im)
            }
        }
    }

    /// `(dc/dΩ, ds/dΩ)` at Ω (rad/s): zero for a load constant over speed.
    pub fn omega_derivative(&self, omega: f64) -> (f64, f64) {
        match &self.speed {
            None => (0.0, 0.0),
            Some(law) => {
                let z = num_complex::Complex64::new(self.cos, self.sin) * law.derivative(omega);
                (z.re, z.im)
            }
        }
    }

    /// `true` if the load is zero at every speed.
    pub fn is_zero(&self) -> bool {
        self.cos == 0.0 && self.sin == 0.0
    }
}
