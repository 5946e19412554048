//! Anderson acceleration (Walker & Ni 2011, "Anderson acceleration for fixed-point
//! iterations") of the paper's fixed point on the torus: with the fixed-point step
//! `f_k = -γ G R(U_k)` and the last `m` differences `ΔF`, `ΔU`,
//!
//! `θ = argmin ‖f_k - ΔF θ‖`, `U_{k+1} = U_k + f_k - (ΔU + ΔF) θ`,
//!
//! least squares over the real and imaginary parts (the torus map is real-linear, not
//! complex-linear). Same cost per iteration as the fixed point, far fewer iterations where the
//! rest is not weak.

use super::fixed_point::{receptance_step, Watch};
use super::newton_krylov::{finish, relative_residual, start_of};
use super::{TorusBalance, TorusSolution};
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::collections::VecDeque;

/// Anderson settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusAnderson {
    /// Relaxation γ of the underlying fixed point, in (0, 1].
    pub gamma: f64,
    /// Differences kept (the depth m, 1..=50).
    pub depth: usize,
    /// Converged at `‖R‖ <= tolerance · max(‖L‖, ‖G⁻¹ U‖)`.
    pub tolerance: f64,
    /// Most iterations.
    pub max_iterations: usize,
}

impl Default for TorusAnderson {
    fn default() -> Self {
        Self {
            gamma: 1.0,
            depth: 8,
            tolerance: 1e-10,
            max_iterations: 300,
        }
    }
}

/// A complex vector as the reals `(re, im, re, im, …)`.
fn real(x: &[Complex64]) -> DVector<f64> {
    DVector::from_iterator(2 * x.len(), x.iter().flat_map(|v| [v.re, v.im]))
}

impl TorusAnderson {
    /// Iterates from `start` (the linear response where `None`); the run ends marked not
    /// converged at its best iterate on the iteration limit or divergence (a residual a
    /// thousand times the smallest seen, or not finite).
    pub fn solve(&self, hb: &TorusBalance, start: Option<&[Complex64]>) -> Result<TorusSolution> {
        if !(self.gamma > 0.0 && self.gamma <= 1.0) {
            let e = Error::invalid("torus Anderson", "gamma", self.gamma, "in (0, 1]");
            return Err(e);
        }
        if !(1..=50).contains(&self.depth) {
            let e = Error::invalid("torus Anderson", "depth", self.depth as f64, "in 1..=50");
            return Err(e);
        }
        let mut ws = hb.workspace();
        let mut u = start_of(hb, start)?;
        let len = hb.len();
        if len == 0 {
            return finish(hb, &u, &mut ws, 0.0, true, 0, 0);
        }
        let mut r = vec![Complex64::default(); len];
        let mut f = vec![Complex64::default(); len];
        let mut watch = Watch::new(&u, self.tolerance, self.max_iterations);
        let mut history: VecDeque<(DVector<f64>, DVector<f64>)> = VecDeque::new();
        let mut last: Option<(DVector<f64>, DVector<f64>)> = None;
        let mut iterations = 0;
        let converged = loop {
            hb.residual_into(&u, &mut r, false, &mut ws)?;
            if let Some(converged) = watch.observe(&u, relative_residual(hb, &u, &r), iterations) {
                break converged;
            }
            iterations += 1;
            receptance_step(hb, &r, self.gamma, &mut f);
            let (uk, fk) = (real(&u), real(&f));
            if let Some((u0, f0)) = last.take() {
                history.push_back((&uk - u0, &fk - f0));
                if history.len() > self.depth {
                    history.pop_front();
                }
            }
            let mut next = &uk + &fk;
            if !history.is_empty() {
                let df =
                    DMatrix::from_columns(&history.iter().map(|h| h.1.clone()).collect::<Vec<_>>());
                if let Ok(theta) = df.clone().svd(true, true).solve(&fk, 1e-12) {
                    for (i, (du, dfi)) in history.iter().enumerate() {
                        next -= (du + dfi) * theta[i];
                    }
                }
            }
            for (j, v) in u.iter_mut().enumerate() {
                *v = Complex64::new(next[2 * j], next[2 * j + 1]);
            }
            last = Some((uk, fk));
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
