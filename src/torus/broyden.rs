//! Broyden's ("good") method on the condensed torus balance: no Jacobian products at all, a
//! secant update of the inverse Jacobian started from the block-diagonal averaged Jacobian
//! of Newton–Krylov's preconditioner (Broyden 1965; the limited-memory product form of
//! Kelley, *Iterative Methods for Linear and Nonlinear Equations*, SIAM 1995, §7.3).
//!
//! `H_{i+1} = H_i + (s_i − H_i y_i) s_iᵀ H_i / (s_iᵀ H_i y_i)`, with `s_i` the step taken and
//! `y_i` the change of the residual, applied as `z_0 = H_0 x`,
//! `z_{i+1} = z_i + p_i (s_i·z_i) / d_i`, `p_i = s_i − H_i y_i`, `d_i = s_i·H_i y_i`, over the
//! real inner product of the complex unknowns (the balance is real-linear, not complex-linear).
//! The memory restarts from the averaged Jacobian at the current state when full.

use super::newton_krylov::{
    apply_blocks, finish, line_search, norm, preconditioner, relative_residual, start_of,
};
use super::{TorusBalance, TorusSolution};
use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Consecutive uphill steps before the run ends.
const MAX_RESTARTS: usize = 3;

/// Steps in a row with a residual 100 times its best before a run is taken as lost (it
/// wandered off; a run that comes back does so well within this).
const MAX_LOST: usize = 60;

/// Broyden settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusBroyden {
    /// Converged at `‖R‖ <= tolerance · max(‖L‖, ‖G⁻¹ U‖)`.
    pub tolerance: f64,
    /// Most steps (residual evaluations besides the line search's).
    pub max_iterations: usize,
    /// Secant updates kept before a restart from the averaged Jacobian.
    pub memory: usize,
}

impl Default for TorusBroyden {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 200,
            memory: 40,
        }
    }
}

/// `Σ Re(conj(a) b)`: the real inner product of the unknowns as real numbers.
fn dot(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.re * y.re + x.im * y.im)
        .sum()
}

/// The inverse-Jacobian estimate: `H_0` (blocks) and the secant pairs `(s_i, p_i / d_i)`.
struct Inverse {
    blocks: Vec<DMatrix<Complex64>>,
    m: usize,
    pairs: Vec<(Vec<Complex64>, Vec<Complex64>)>,
}

impl Inverse {
    /// `x ← H x`.
    fn apply(&self, x: &mut [Complex64]) {
        apply_blocks(&self.blocks, self.m, x);
        for (s, q) in &self.pairs {
            let c = dot(s, x);
            for (z, p) in x.iter_mut().zip(q) {
                *z += p * c;
            }
        }
    }
}

impl TorusBroyden {
    /// Solves `hb` from `start` (the linear response where `None`). A step that does not
    /// lower the residual after 12 halvings is taken in full (uphill: its secant pair carries
    /// what the averaged Jacobian misses where a contact opens); the fourth such step in a
    /// row ends the run at the best iterate, marked not converged, as do 60 steps in a row
    /// whose residual is 100 times the best (a run that wandered off).
    pub fn solve(&self, hb: &TorusBalance, start: Option<&[Complex64]>) -> Result<TorusSolution> {
        let mut ws = hb.workspace();
        let mut u = start_of(hb, start)?;
        let len = hb.len();
        let mut r = vec![Complex64::default(); len];
        let (mut iterations, mut relative, mut converged) = (0, 0.0, len == 0);
        if len > 0 {
            hb.residual_into(&u, &mut r, true, &mut ws)?;
            let fresh = |ws: &_| Inverse {
                blocks: preconditioner(hb, ws),
                m: hb.coordinates(),
                pairs: Vec::new(),
            };
            let mut h = fresh(&ws);
            let mut failures = 0;
            // The best iterate, which a run that stops after uphill steps returns.
            let mut best = (norm(&r), u.clone());
            let (mut best_relative, mut lost) = (f64::INFINITY, 0);
            loop {
                relative = relative_residual(hb, &u, &r);
                if relative <= self.tolerance {
                    converged = true;
                    break;
                }
                if norm(&r) < best.0 {
                    best = (norm(&r), u.clone());
                }
                best_relative = best_relative.min(relative);
                lost = if relative > 100.0 * best_relative {
                    lost + 1
                } else {
                    0
                };
                if iterations >= self.max_iterations || failures > MAX_RESTARTS || lost >= MAX_LOST
                {
                    if norm(&r) > best.0 {
                        u = best.1;
                        hb.residual_into(&u, &mut r, false, &mut ws)?;
                        relative = relative_residual(hb, &u, &r);
                    }
                    break;
                }
                iterations += 1;
                let mut step: Vec<Complex64> = r.iter().map(|v| -v).collect();
                h.apply(&mut step);
                let (u_old, r_old) = (u.clone(), r.clone());
                if line_search(hb, &mut u, &mut r, &step, false, &mut ws)?.is_none() {
                    failures += 1;
                    // A full step uphill (non-monotone): the secant pair it gives carries
                    // what the averaged Jacobian misses where a contact opens.
                    for (x, s) in u.iter_mut().zip(&step) {
                        *x += s;
                    }
                    hb.residual_into(&u, &mut r, false, &mut ws)?;
                } else {
                    failures = 0;
                }
                if h.pairs.len() >= self.memory {
                    // The averaged Jacobian at the current state (the line search evaluates
                    // forces only).
                    hb.residual_into(&u, &mut r, true, &mut ws)?;
                    h = fresh(&ws);
                    continue;
                }
                let s: Vec<Complex64> = u.iter().zip(&u_old).map(|(a, b)| a - b).collect();
                let mut hy: Vec<Complex64> = r.iter().zip(&r_old).map(|(a, b)| a - b).collect();
                h.apply(&mut hy);
                let d = dot(&s, &hy);
                if d.abs() > 1e-300 && d.is_finite() && norm(&s) > 0.0 {
                    let q = s.iter().zip(&hy).map(|(a, b)| (a - b) / d).collect();
                    h.pairs.push((s, q));
                }
            }
        }
        finish(hb, &u, &mut ws, relative, converged, iterations, 0)
    }
}
