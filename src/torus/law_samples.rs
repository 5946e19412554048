//! The laws on the torus grid: every element's force (and its derivatives) at the grid's
//! samples of its coordinate, evaluated line by line along its own base's axis and corrected
//! where a contact edge is crossed between samples ([`super::edges`]).

use super::elements::TorusElement;
use super::{TorusBalance, TorusWorkspace};
use crate::error::{Error, Result};
use num_complex::Complex64;
use std::f64::consts::TAU;

impl TorusBalance<'_> {
    /// The rest's samples per coordinate into `ws.force` (and the derivative samples).
    pub(super) fn force_samples(
        &self,
        u: &[Complex64],
        derivatives: bool,
        ws: &mut TorusWorkspace,
    ) -> Result<()> {
        for c in 0..self.coordinates() {
            self.synthesize(u, c, false, &mut ws.u[c], &mut ws.fft);
            self.synthesize(u, c, true, &mut ws.du[c], &mut ws.fft);
            self.note_reach(u, c, ws);
            ws.ffts += 2;
            ws.force[c].fill(0.0);
            if derivatives {
                ws.gu[c].fill(0.0);
                ws.gdu[c].fill(0.0);
            }
        }
        for act in &self.active {
            self.element_force(act, derivatives, ws)?;
        }
        Ok(())
    }

    /// One element's rest into its coordinate's force samples (and derivative samples).
    pub(super) fn element_force(
        &self,
        act: &TorusElement,
        derivatives: bool,
        ws: &mut TorusWorkspace,
    ) -> Result<()> {
        let e = &self.tm.model().elements()[act.index];
        let law = act.band_limited.as_deref().unwrap_or(e.law());
        let (c, s, lin) = (act.coordinate, act.factor, act.linear);
        // The base's angle at grid point p (for the samples on the law's time jumps).
        let (n, stride) = self.axis(act.base);
        let line = &self.line_thetas[act.base];
        let theta = |p: usize| line[(p / stride) % n];
        let delta = 1e-7 * TAU / self.fft.dims()[act.base] as f64;
        self.law_samples(act, ws);
        for (((f, &x), &v), acc) in ws.fe.iter().zip(&ws.ue).zip(&ws.due).zip(&mut ws.force[c]) {
            let rest = f - lin.offset - lin.stiffness * x - lin.damping * v;
            if !rest.is_finite() {
                return Err(Error::NonFinite {
                    what: format!(
                        "the force of element `{}` on the torus grid (u = {x:e}, u̇ = {v:e})",
                        e.name()
                    ),
                });
            }
            *acc += s * rest;
        }
        if derivatives {
            self.law_batches(act.base, law, true, ws);
            for &p in &act.jumps {
                let (t, x, v) = (theta(p), ws.ue[p], ws.due[p]);
                let (a0, b0) = law.derivatives(t - delta, x, v);
                let (a1, b1) = law.derivatives(t + delta, x, v);
                (ws.ge[p], ws.gde[p]) = (0.5 * (a0 + a1), 0.5 * (b0 + b1));
            }
            self.correct_edge_derivatives(act, ws);
            let s2 = s * s;
            for p in 0..ws.ge.len() {
                let (a, b) = (ws.ge[p] - lin.stiffness, ws.gde[p] - lin.damping);
                if !(a.is_finite() && b.is_finite()) {
                    return Err(Error::NonFinite {
                        what: format!("the force derivatives of element `{}`", e.name()),
                    });
                }
                ws.gu[c][p] += s2 * a;
                ws.gdu[c][p] += s2 * b;
            }
        }
        Ok(())
    }

    /// The element's coordinate `u_e = s u_c` and its rate into `ws.ue`, `ws.due` (from
    /// `ws.u`, `ws.du`) and its law's force at every grid point into `ws.fe`, the samples on
    /// the law's time jumps averaged across the jump.
    pub(super) fn law_samples(&self, act: &TorusElement, ws: &mut TorusWorkspace) {
        let law = act
            .band_limited
            .as_deref()
            .unwrap_or(self.tm.model().elements()[act.index].law());
        let (c, s) = (act.coordinate, act.factor);
        for (x, &v) in ws.ue.iter_mut().zip(&ws.u[c]) {
            *x = s * v;
        }
        for (x, &v) in ws.due.iter_mut().zip(&ws.du[c]) {
            *x = s * v;
        }
        self.law_batches(act.base, law, false, ws);
        let (n, stride) = self.axis(act.base);
        let line = &self.line_thetas[act.base];
        let delta = 1e-7 * TAU / self.fft.dims()[act.base] as f64;
        for &p in &act.jumps {
            let (t, x, v) = (line[(p / stride) % n], ws.ue[p], ws.due[p]);
            ws.fe[p] = 0.5 * (law.force(t - delta, x, v) + law.force(t + delta, x, v));
        }
        self.correct_edge_forces(act, law, ws);
    }

    /// The law's force at every grid point into `ws.fe` (or its derivatives into `ws.ge`,
    /// `ws.gde`), from `ws.ue`, `ws.due`, evaluated line by line along the base's own axis: every
    /// batch a law sees is its base's equidistant angles in order, never the angles repeated
    /// along the other axes (a law may take a shortcut on equidistant angles, as
    /// [`MeshProfile::values_into`](crate::force::MeshProfile::values_into) does).
    #[allow(clippy::needless_range_loop)] // j indexes the line and, through `at`, the grid
    pub(super) fn law_batches(
        &self,
        base: usize,
        law: &dyn crate::force::ForceLaw,
        derivatives: bool,
        ws: &mut TorusWorkspace,
    ) {
        let (n, stride) = self.axis(base);
        let theta = &self.line_thetas[base];
        let lines = &mut ws.lines;
        for o in 0..self.fft.points() / (n * stride) {
            for i in 0..stride {
                let at = |j: usize| o * n * stride + j * stride + i;
                for j in 0..n {
                    (lines[0][j], lines[1][j]) = (ws.ue[at(j)], ws.due[at(j)]);
                }
                let [u, du, f, g, ..] = lines;
                let (u, du) = (&u[..n], &du[..n]);
                if derivatives {
                    law.derivatives_batch(theta, u, du, &mut f[..n], &mut g[..n]);
                    for j in 0..n {
                        (ws.ge[at(j)], ws.gde[at(j)]) = (f[j], g[j]);
                    }
                } else {
                    law.force_batch(theta, u, du, &mut f[..n]);
                    for j in 0..n {
                        ws.fe[at(j)] = f[j];
                    }
                }
            }
        }
    }

    /// The samples `N_b` of base b's axis and its stride in the grid.
    pub(super) fn axis(&self, base: usize) -> (usize, usize) {
        let dims = self.fft.dims();
        (dims[base], dims[base + 1..].iter().product())
    }
}
