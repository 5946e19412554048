//! The paper's fixed point on the condensed torus balance (Bauer et al. 2021, eq. (9) with
//! relaxation): solve the linear part per line with the rest on the right-hand side,
//!
//! `U ← (1 - γ) U + γ G (L - N(U)) = U - γ G R(U)`,
//!
//! one AFT and one m × m product per line and iteration. It converges where the rest is weak
//! against the linear part (a closed contact, a mild nonlinearity); Newton–Krylov
//! ([`super::NewtonKrylov`]) where it is not.

use super::newton_krylov::{finish, relative_residual, start_of};
use super::{TorusBalance, TorusSolution};
use crate::error::{Error, Result};
use num_complex::Complex64;

/// Fixed-point settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusFixedPoint {
    /// Relaxation γ in (0, 1].
    pub gamma: f64,
    /// Converged at `‖R‖ <= tolerance · max(‖L‖, ‖G⁻¹ U‖)`.
    pub tolerance: f64,
    /// Most iterations.
    pub max_iterations: usize,
}

impl Default for TorusFixedPoint {
    fn default() -> Self {
        Self {
            gamma: 1.0,
            tolerance: 1e-10,
            max_iterations: 500,
        }
    }
}

impl TorusFixedPoint {
    /// Iterates from `start` (the linear response where `None`) until the tolerance, the
    /// iteration limit, or divergence (a residual a thousand times the smallest seen, or not
    /// finite), which ends the run marked not converged at the best iterate.
    pub fn solve(&self, hb: &TorusBalance, start: Option<&[Complex64]>) -> Result<TorusSolution> {
        if !(self.gamma > 0.0 && self.gamma <= 1.0) {
            return Err(Error::invalid(
                "torus fixed point",
                "gamma",
                self.gamma,
                "in (0, 1]",
            ));
        }
        let mut ws = hb.workspace();
        let mut u = start_of(hb, start)?;
        let (len, m) = (hb.len(), hb.coordinates());
        let mut r = vec![Complex64::default(); len];
        let (mut best, mut best_u) = (f64::INFINITY, u.clone());
        let mut iterations = 0;
        let mut converged = false;
        if len == 0 {
            return finish(hb, &u, &mut ws, 0.0, true, 0, 0);
        }
        loop {
            hb.residual_into(&u, &mut r, false, &mut ws)?;
            let relative = relative_residual(hb, &u, &r);
            if relative < best {
                (best, best_u) = (relative, u.clone());
            }
            if relative <= self.tolerance {
                converged = true;
                break;
            }
            if iterations >= self.max_iterations || !relative.is_finite() || relative > 1e3 * best {
                break;
            }
            iterations += 1;
            for (j, g) in hb.linear.receptance.iter().enumerate() {
                for a in 0..m {
                    let step: Complex64 = (0..m).map(|b| g[(a, b)] * r[j * m + b]).sum();
                    u[j * m + a] -= step * self.gamma;
                }
            }
        }
        finish(hb, &best_u, &mut ws, best, converged, iterations, 0)
    }
}
