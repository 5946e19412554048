//! The argmin problem adapter: the harmonic residual with its buffers behind a `RefCell`
//! (argmin's problem traits take `&self`).

use super::coarse::CoarseBlock;
use crate::error::Result;
use crate::harmonic::RealLayout;
use crate::residual::{HarmonicBalance, Workspace};
use nalgebra::DMatrix;
use std::cell::RefCell;

/// `R(x)` on real unknowns, its Jacobian, and the paper's fixed-point map, for the solvers.
pub struct HbProblem<'a, 'm> {
    hb: &'a HarmonicBalance<'m>,
    ws: RefCell<&'a mut Workspace>,
    ext_norm: f64,
    coarse: Option<&'a CoarseBlock>,
}

impl<'a, 'm> HbProblem<'a, 'm> {
    /// Wraps `hb` and the workspace the solve may use.
    pub fn new(hb: &'a HarmonicBalance<'m>, ws: &'a mut Workspace) -> Self {
        let ext_norm = hb.norm(hb.external_load());
        Self {
            hb,
            ws: RefCell::new(ws),
            ext_norm,
            coarse: None,
        }
    }

    /// The same problem with the two-level map: [`fixed_point_map`](Self::fixed_point_map)
    /// steps the harmonics `0..=H_c` with the coarse Jacobian's factors.
    pub fn with_coarse(mut self, coarse: Option<&'a CoarseBlock>) -> Self {
        self.coarse = coarse.filter(|c| c.harmonics() < self.hb.basis().harmonics());
        self
    }

    /// The discretised model.
    pub fn hb(&self) -> &'a HarmonicBalance<'m> {
        self.hb
    }

    /// The real layout.
    pub fn layout(&self) -> RealLayout {
        self.hb.layout()
    }

    /// The relative residual `‖R‖ / ‖F_ext‖` (without a load, relative to
    /// `max(‖Z Q‖, ‖F_rest‖)`), from the buffers of the last evaluation.
    fn relative(&self, ws: &Workspace, r_norm: f64) -> f64 {
        let scale = if self.ext_norm > 0.0 {
            self.ext_norm
        } else {
            self.hb.norm(&ws.zq).max(self.hb.norm(&ws.rest))
        };
        if scale > 0.0 {
            r_norm / scale
        } else {
            r_norm
        }
    }

    /// `r ← R(x)` (and `jac ← ∂R/∂x`); returns the relative residual.
    pub fn residual(
        &self,
        x: &[f64],
        r: &mut [f64],
        jac: Option<&mut DMatrix<f64>>,
    ) -> Result<f64> {
        let mut ws = self.ws.borrow_mut();
        if jac.is_some() {
            ws.stats.jacobians += 1;
        }
        ws.stats.residual_evaluations += 1;
        self.hb.residual_real_into(x, r, jac, &mut ws)?;
        let rel = self.relative(&ws, self.layout().norm(r));
        if !rel.is_finite() {
            return Err(self.non_finite("the residual", r));
        }
        Ok(rel)
    }

    /// The error for a non-finite `what` in the real layout `v`: its first non-finite entry,
    /// or, where every entry is finite and only the norm overflows, its largest, named by
    /// harmonic and unknown (a DOF, or `u(element)` when condensed).
    fn non_finite(&self, what: &str, v: &[f64]) -> crate::Error {
        let n = self.layout().n.max(1);
        let (index, overflow) = match v.iter().position(|x| !x.is_finite()) {
            Some(i) => (i, false),
            None => (
                (0..v.len())
                    .max_by(|&a, &b| v[a].abs().total_cmp(&v[b].abs()))
                    .unwrap_or(0),
                true,
            ),
        };
        let block = index / n;
        let k = block.div_ceil(2);
        let part = if block == 0 || block % 2 == 1 {
            "cos"
        } else {
            "sin"
        };
        let name = self
            .hb
            .unknown_names()
            .get(index % n)
            .map_or("?", String::as_str);
        crate::Error::NonFinite {
            what: if overflow {
                format!(
                    "the norm of {what} (its largest entry, {:e}, at harmonic {k} ({part}) of \
                     `{name}`, overflows when squared)",
                    v.get(index).copied().unwrap_or(f64::NAN)
                )
            } else {
                format!("{what} at harmonic {k} ({part}) of `{name}`")
            },
        }
    }

    /// The paper's map `g ← G(x) = Z⁻¹ (F_ext - F_rest(x))` (steps 2a-2c, one per-harmonic solve)
    /// and the relative residual at `x` from the same evaluation (`R = Z x - Z G(x)`). With a
    /// [`CoarseBlock`] the harmonics `0..=H_c` take the step `x - J_c⁻¹ R` instead (the
    /// two-level map of [`coarse`](super::coarse)).
    pub fn fixed_point_map(&self, x: &[f64], g: &mut [f64]) -> Result<f64> {
        let mut ws = self.ws.borrow_mut();
        let ws = &mut **ws;
        let hb = self.hb;
        let layout = hb.layout();
        layout.unpack(x, &mut ws.q);
        ws.stats.residual_evaluations += 1;
        hb.rest_into(&ws.q, &mut ws.rest, &mut ws.eval)?;
        let n = layout.n;
        let z = hb.dynamic_stiffness();
        let f_ext = hb.split_load();
        let low = self.coarse.map(|c| (c.harmonics() + 1) * n).unwrap_or(0);
        let mut r2 = 0.0;
        for k in 0..=layout.h {
            let s = k * n..(k + 1) * n;
            z.apply(k, &ws.q[s.clone()], &mut ws.zq[s.clone()]);
            let w = if k == 0 { 1.0 } else { 0.5 };
            for i in s.clone() {
                ws.rhs[i] = f_ext[i] - ws.rest[i];
                r2 += w * (ws.zq[i] - ws.rhs[i]).norm_sqr();
            }
            if s.start >= low {
                z.solve_in_place(k, &mut ws.rhs[s]);
            }
        }
        if let Some(c) = self.coarse {
            // rhs ← R on the low block, then x - J_c⁻¹ R.
            for i in 0..low {
                ws.rhs[i] = ws.zq[i] - ws.rhs[i];
            }
            c.solve_in_place(&mut ws.rhs[..low]);
            for i in 0..low {
                ws.rhs[i] = ws.q[i] - ws.rhs[i];
            }
        }
        layout.pack(&ws.rhs, g);
        let rel = self.relative(ws, r2.sqrt());
        if !(rel.is_finite() && g.iter().all(|v| v.is_finite())) {
            return Err(self.non_finite("the fixed-point map (a linear solve)", g));
        }
        Ok(rel)
    }

    /// The full harmonics of the unknowns `q` (see
    /// [`HarmonicBalance::full_harmonics`]).
    pub fn full_harmonics(
        &self,
        q: &[num_complex::Complex64],
    ) -> Result<Vec<num_complex::Complex64>> {
        let mut ws = self.ws.borrow_mut();
        self.hb.full_harmonics(q, &mut ws.eval)
    }

    /// Counts one solver iteration.
    pub(crate) fn count_iteration(&self) {
        self.ws.borrow_mut().stats.iterations += 1;
    }

    /// Counts one LU factorisation.
    pub(crate) fn count_factorization(&self) {
        self.ws.borrow_mut().stats.factorizations += 1;
    }

    /// `jac ← Z` in the real layout (the block-diagonal dynamic stiffness, without the AFT
    /// part): Broyden's cheap initial Jacobian.
    pub fn dynamic_stiffness_into(&self, jac: &mut DMatrix<f64>) {
        jac.fill(0.0);
        self.hb.add_dynamic_stiffness_real(jac);
    }

    /// Moves the workspace's counters into a result and resets them.
    pub(crate) fn take_stats(&self) -> crate::SolveStats {
        let mut ws = self.ws.borrow_mut();
        let mut stats = ws.stats;
        stats.ffts = ws.eval.ffts;
        stats.force_evaluations = ws.eval.force_evaluations;
        ws.stats = Default::default();
        ws.eval.ffts = 0;
        ws.eval.force_evaluations = 0;
        stats
    }

    /// Resets the counters before a solve.
    pub(crate) fn reset_stats(&self) {
        let _ = self.take_stats();
    }
}
