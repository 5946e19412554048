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
        let len = hb.len();
        if len == 0 {
            return finish(hb, &u, &mut ws, 0.0, true, 0, 0);
        }
        let (mut r, mut f) = (
            vec![Complex64::default(); len],
            vec![Complex64::default(); len],
        );
        let mut watch = Watch::new(&u, self.tolerance, self.max_iterations);
        let mut iterations = 0;
        let converged = loop {
            hb.residual_into(&u, &mut r, false, &mut ws)?;
            if let Some(converged) = watch.observe(&u, relative_residual(hb, &u, &r), iterations) {
                break converged;
            }
            iterations += 1;
            receptance_step(hb, &r, self.gamma, &mut f);
            for (x, s) in u.iter_mut().zip(&f) {
                *x += s;
            }
        };
        finish(
            hb,
            &watch.best_u,
            &mut ws,
            watch.best,
            converged,
            iterations,
            0,
        )
    }
}

/// `out ← -γ G R` per line: the fixed point's step.
pub(super) fn receptance_step(
    hb: &TorusBalance,
    r: &[Complex64],
    gamma: f64,
    out: &mut [Complex64],
) {
    let m = hb.coordinates();
    if hb.linear.receptance_form {
        // R = U + G N − G L already is U − G (L − N).
        for (o, v) in out.iter_mut().zip(r) {
            *o = -v * gamma;
        }
        return;
    }
    for (j, g) in hb.linear.receptance.iter().enumerate() {
        for a in 0..m {
            let s: Complex64 = (0..m).map(|b| g[(a, b)] * r[j * m + b]).sum();
            out[j * m + a] = -s * gamma;
        }
    }
}

/// The best iterate of a fixed-point-type run, and when it stops: at the tolerance, the
/// iteration limit, or divergence (a residual a thousand times the smallest seen, or not
/// finite).
pub(super) struct Watch {
    pub(super) best: f64,
    pub(super) best_u: Vec<Complex64>,
    tolerance: f64,
    max_iterations: usize,
}

impl Watch {
    pub(super) fn new(u: &[Complex64], tolerance: f64, max_iterations: usize) -> Self {
        Self {
            best: f64::INFINITY,
            best_u: u.to_vec(),
            tolerance,
            max_iterations,
        }
    }

    /// Records `u` with its relative residual after `iterations`; `Some(converged)` where the
    /// run stops.
    pub(super) fn observe(
        &mut self,
        u: &[Complex64],
        relative: f64,
        iterations: usize,
    ) -> Option<bool> {
        if relative < self.best {
            self.best = relative;
            self.best_u.copy_from_slice(u);
        }
        if relative <= self.tolerance {
            return Some(true);
        }
        let diverged = !relative.is_finite() || relative > 1e3 * self.best;
        (iterations >= self.max_iterations || diverged).then_some(false)
    }
}
