//! The AFT of an element whose law has memory ([`Hysteresis`]): its rest force by marching
//! the samples until the loop closes, its exact Jacobian block and its Ω-derivative (see
//! [`crate::harmonic::march`]).
//!
//! The Jacobian block of such an element is the projection of the `N × (2H+1)` sample
//! derivatives `∂f_j/∂x_c` (directions: the local unknowns `a_0, a_l, b_l` of `u`, with
//! `∂u_j/∂a_l = cos lθ_j`, `∂u̇_j/∂a_l = -lΩ sin lθ_j`, `∂u_j/∂b_l = sin lθ_j`,
//! `∂u̇_j/∂b_l = lΩ cos lθ_j`), minus the linear part `k0 ∂u_j/∂x_c + d0 ∂u̇_j/∂x_c`, onto the
//! harmonics: one FFT per column. It is a general `(2H+1)²` matrix, not the Toeplitz-like
//! block of a memoryless law.

use super::aft::{scatter_add, ActiveElement};
use super::{AftBuffers, HarmonicBalance};
use crate::error::{Error, Result};
use crate::force::{Hysteresis, LinearPart};
use crate::harmonic::march::{march, NotClosed};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// `cos`, `sin` of `2π m / N`, `m = 0..N`: the sample values of every harmonic
/// (`lθ_j = 2π (l j mod N) / N`).
pub(super) fn trig_table(samples: usize) -> Vec<(f64, f64)> {
    (0..samples)
        .map(|m| {
            let t = std::f64::consts::TAU * m as f64 / samples as f64;
            (t.cos(), t.sin())
        })
        .collect()
}

/// `(∂u_j/∂x_c, ∂u̇_j/∂x_c)` for the local unknown `c` (real layout: `a_0`, then `a_l` at
/// `2l - 1`, `b_l` at `2l`).
#[inline]
fn direction(trig: &[(f64, f64)], omega: f64, j: usize, c: usize) -> (f64, f64) {
    if c == 0 {
        return (1.0, 0.0);
    }
    let l = c.div_ceil(2);
    let (cos, sin) = trig[(l * j) % trig.len()];
    let lw = l as f64 * omega;
    if c % 2 == 1 {
        (cos, -lw * sin)
    } else {
        (sin, lw * cos)
    }
}

/// The error of a loop that does not close, naming the element.
fn not_closed(element: &str, e: NotClosed) -> Error {
    Error::Solver {
        reason: format!(
            "element `{element}`: the hysteresis loop did not close after {} passes over the period (last change of the state {:.1e})",
            e.passes, e.change
        ),
    }
}

impl HarmonicBalance<'_> {
    /// `out += w F_rest` of the memory element `act` (its samples in `ws.u`, `ws.du`, local
    /// harmonics in `ws.uk`), and with `jac` its Jacobian block.
    pub(super) fn memory_rest(
        &self,
        act: &ActiveElement,
        law: &dyn Hysteresis,
        lin: &LinearPart,
        out: &mut [Complex64],
        jac: Option<&mut DMatrix<f64>>,
        ws: &mut AftBuffers,
    ) -> Result<()> {
        let e = &self.model.elements()[act.index];
        let (n, h, samples) = (self.n, self.basis.harmonics(), self.basis.samples());
        let omega = self.basis.fundamental();
        let columns = if jac.is_some() { 2 * h + 1 } else { 0 };
        let trig = &self.trig;
        let passes = march(
            law,
            &self.thetas,
            &ws.u,
            &ws.du,
            &mut ws.f,
            columns,
            |j, c| direction(trig, omega, j, c),
            &mut ws.march,
        )
        .map_err(|x| not_closed(e.name(), x))?;
        ws.force_evaluations += passes * samples;
        for ((f, &u), &du) in ws.f.iter_mut().zip(&ws.u).zip(&ws.du) {
            *f -= lin.offset + lin.stiffness * u + lin.damping * du;
        }
        self.samples(ws).check("force", e.name(), &ws.f)?;
        self.aft.analyze_into(&mut ws.f, &mut ws.uk, &mut ws.aft);
        ws.ffts += 3;
        for k in 0..=h {
            scatter_add(&act.weights, ws.uk[k], &mut out[k * n..(k + 1) * n]);
        }
        let Some(jac) = jac else {
            return Ok(());
        };
        let rows = jac.nrows();
        let data = jac.as_mut_slice();
        for c in 0..columns {
            let dfdx = &ws.march.dfdx[c * samples..(c + 1) * samples];
            for (j, (g, &d)) in ws.gu.iter_mut().zip(dfdx).enumerate() {
                let (pu, pv) = direction(trig, omega, j, c);
                *g = d - lin.stiffness * pu - lin.damping * pv;
            }
            self.samples(ws)
                .check("force derivative", e.name(), &ws.gu)?;
            self.aft.analyze_into(&mut ws.gu, &mut ws.uk, &mut ws.aft);
            ws.ffts += 1;
            ws.column[0] = ws.uk[0].re;
            for k in 1..=h {
                ws.column[2 * k - 1] = ws.uk[k].re;
                ws.column[2 * k] = -ws.uk[k].im;
            }
            crate::jacobian::add_local_column(&ws.column, c, &act.weights, n, data, rows);
        }
        Ok(())
    }

    /// The Ω-derivative of the rest of the memory element `act` at the samples into `ws.f`:
    /// the march's derivative along `∂u̇_j/∂Ω = u̇_j/Ω` (u itself does not move with Ω),
    /// minus `d0 u̇_j/Ω`.
    pub(super) fn memory_omega_derivative(
        &self,
        act: &ActiveElement,
        law: &dyn Hysteresis,
        ws: &mut AftBuffers,
    ) -> Result<()> {
        let e = &self.model.elements()[act.index];
        let omega = self.basis.omega();
        let d0 = e.linear_part().damping;
        let du = &ws.du;
        march(
            law,
            &self.thetas,
            &ws.u,
            du,
            &mut ws.gdu,
            1,
            |j, _| (0.0, du[j] / omega),
            &mut ws.march,
        )
        .map_err(|x| not_closed(e.name(), x))?;
        let samples = self.basis.samples();
        for ((f, &g), &v) in ws.f.iter_mut().zip(&ws.march.dfdx[..samples]).zip(du) {
            *f = g - d0 * v / omega;
        }
        Ok(())
    }
}
