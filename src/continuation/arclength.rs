//! The pseudo-arclength predictor–corrector (see the module documentation of
//! [`continuation`](super)).

// The corrector indexes several vectors in lock step.
#![allow(clippy::needless_range_loop)]

use super::point::NewPoint;
use super::{Branch, BranchStop, Continuation};
use crate::error::{Error, Result};
use crate::harmonic::RealLayout;
use crate::model::Model;
use crate::residual::{HarmonicBalance, Workspace};
use crate::solve::{lu, robust_start};
use crate::HarmonicBasis;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Buffers of the corrector.
struct Bordered {
    layout: RealLayout,
    r: Vec<f64>,
    r_omega: Vec<f64>,
    jac: DMatrix<f64>,
    big: DMatrix<f64>,
    perm: Vec<usize>,
    rhs: Vec<f64>,
}

impl Bordered {
    fn new(layout: RealLayout) -> Self {
        let m = layout.len();
        Self {
            layout,
            r: vec![0.0; m],
            r_omega: vec![0.0; m],
            jac: DMatrix::zeros(m, m),
            big: DMatrix::zeros(m + 1, m + 1),
            perm: vec![0; m + 1],
            rhs: vec![0.0; m + 1],
        }
    }

    /// Evaluates R, R_x, R_Ω at (x, Ω) and factors the bordered matrix with last row `t`.
    /// Returns the relative residual, or None if singular.
    #[allow(clippy::too_many_arguments)]
    fn factor(
        &mut self,
        hb: &mut HarmonicBalance,
        ws: &mut Workspace,
        x: &[f64],
        omega: f64,
        t: &[f64],
        sx: f64,
        so: f64,
        ext: f64,
    ) -> Result<Option<f64>> {
        if (hb.basis().omega() - omega).abs() > 0.0 {
            hb.set_omega(omega)?;
        }
        hb.residual_real_into(x, &mut self.r, Some(&mut self.jac), ws)?;
        hb.omega_derivative_real_into(x, &mut self.r_omega, ws)?;
        let m = self.layout.len();
        for (j, tj) in t.iter().enumerate().take(m) {
            for i in 0..m {
                self.big[(i, j)] = self.jac[(i, j)] * sx;
            }
            self.big[(m, j)] = *tj;
        }
        for i in 0..m {
            self.big[(i, m)] = self.r_omega[i] * so;
        }
        self.big[(m, m)] = t[m];
        let rel = self.layout.norm(&self.r) / ext;
        if !rel.is_finite() {
            return Err(Error::NonFinite {
                what: "residual on the branch".into(),
            });
        }
        Ok(lu::factor_in_place(&mut self.big, &mut self.perm).then_some(rel))
    }
}

/// A corrector target: the predicted point `(x_p, Ω_p)` and the last row `t` of the bordered
/// system (the tangent for a pseudo-arclength step, `e_Ω` to land on a given Ω).
struct Target<'a> {
    xp: &'a [f64],
    op: f64,
    row: &'a [f64],
}

/// The scales of the unknowns: `s_x` (the RMS of the current point) and `s_Ω`.
#[derive(Clone, Copy)]
struct Scales {
    sx: f64,
    so: f64,
    ext: f64,
}

impl Scales {
    /// The predictor `(x, Ω) + s t` in the scaled unknowns: writes `x_p`, returns `Ω_p`.
    fn predict(&self, x: &[f64], omega: f64, t: &[f64], s: f64, xp: &mut [f64]) -> f64 {
        let m = x.len();
        for i in 0..m {
            xp[i] = x[i] + s * t[i] * self.sx;
        }
        omega + s * t[m] * self.so
    }
}

impl Continuation {
    /// Defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// Follows the branch of `model` from `basis.omega()` towards `to` (either direction),
    /// calling `progress` with the fraction of the range covered.
    pub fn run(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        to: f64,
        progress: impl FnMut(f64),
    ) -> Result<Branch> {
        self.run_from(model, basis, to, None, progress)
    }

    /// As [`Continuation::run`], with the first point solved from `initial` (harmonic-major
    /// `(H+1)·n`, e.g. a previous result) instead of the linear start. The first point uses
    /// [`Continuation::method`] and falls back to the other solvers and a load homotopy
    /// ([`robust_start`]).
    pub fn run_from(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        to: f64,
        initial: Option<&[Complex64]>,
        mut progress: impl FnMut(f64),
    ) -> Result<Branch> {
        crate::error::check_positive("continuation", "to", to)?;
        let from = basis.omega();
        let mut hb = HarmonicBalance::new(model, basis)?;
        crate::solve::check_dense_for_continuation(&hb)?;
        if let Some(q) = initial {
            if q.len() != hb.len() {
                return Err(Error::DimensionMismatch {
                    context: "continuation start".into(),
                    expected: format!(
                        "{} harmonics (H + 1 = {} per DOF)",
                        hb.len(),
                        basis.harmonics() + 1
                    ),
                    got: format!("{}", q.len()),
                });
            }
        }
        let mut ws = hb.workspace();
        let layout = hb.layout();
        let m = layout.len();
        let mut start = robust_start(&mut hb, &self.method, initial, self.tolerance, &mut ws)?;
        if !start.solution.is_converged() && self.stability.is_some() {
            // Last resort (the inner continuation runs without stability, so no recursion).
            start = super::solve_robustly(model, basis, self)?;
        }
        let mut branch = Branch {
            dofs: model.dof_names().to_vec(),
            harmonics: basis.harmonics(),
            points: Vec::new(),
            start: start.how.clone(),
            stop: BranchStop::Reached,
        };
        let start = start.solution;
        if !start.is_converged() {
            branch.stop = BranchStop::StartFailed {
                reason: branch.start.clone(),
            };
            return Ok(branch);
        }
        // Residuals relative to the load (or the load of the split, or 1 without either).
        let ext = [hb.norm(hb.external_load()), hb.norm(hb.split_load()), 1.0]
            .into_iter()
            .find(|v| *v > 0.0)
            .unwrap_or(1.0);
        let mut x = vec![0.0; m];
        layout.pack(start.harmonics(), &mut x);
        let rms = |x: &[f64]| (layout.norm(x) / (m as f64).sqrt()).max(1e-12 * ext.max(1.0));
        let mut sc = Scales {
            sx: rms(&x),
            so: from,
            ext,
        };
        let direction = if to >= from { 1.0 } else { -1.0 };
        let mut bordered = Bordered::new(layout);
        // Initial tangent from R_x dx = -R_Ω: t ∝ (dx/dΩ · s_Ω/s_x, 1).
        let mut t = vec![0.0; m + 1];
        t[m] = 1.0;
        if bordered
            .factor(&mut hb, &mut ws, &x, from, &t, sc.sx, sc.so, sc.ext)?
            .is_none()
        {
            branch.stop = BranchStop::Singular { omega: from };
            return Ok(branch);
        }
        self.tangent(&mut bordered, &mut t);
        if t[m] * direction < 0.0 {
            t.iter_mut().for_each(|v| *v = -*v);
        }
        let mut omega = from;
        if let Some(reason) = self.push(
            &mut branch,
            model,
            &hb,
            &x,
            omega,
            start.residual(),
            false,
            None,
        ) {
            branch.stop = BranchStop::StabilityFailed { omega, reason };
            return Ok(branch);
        }
        let mut step = self.initial_step;
        let (mut xp, mut x_new) = (vec![0.0; m], vec![0.0; m]);
        let mut land_row = vec![0.0; m + 1];
        land_row[m] = 1.0;
        while branch.points.len() < self.max_points {
            let op = sc.predict(&x, omega, &t, step, &mut xp);
            x_new.copy_from_slice(&xp);
            let mut o_new = op;
            let target = Target {
                xp: &xp,
                op,
                row: &t,
            };
            let Some((iterations, mut rel)) = self.correct(
                &mut bordered,
                &mut hb,
                &mut ws,
                &mut x_new,
                &mut o_new,
                &target,
                sc,
            ) else {
                step *= 0.5;
                if step < self.min_step {
                    branch.stop = BranchStop::StepTooSmall { omega };
                    break;
                }
                continue;
            };
            // Tangent at the new point (bordered matrix factored there with the old t).
            let old_t_omega = t[m];
            let t_prev = t.clone();
            self.tangent(&mut bordered, &mut t);
            let turn = old_t_omega * t[m] < 0.0;
            let turn_omega = if turn {
                let prev_t = t_prev.clone();
                let h = ((0..m)
                    .map(|i| ((x_new[i] - x[i]) / sc.sx).powi(2))
                    .sum::<f64>()
                    + ((o_new - omega) / sc.so).powi(2))
                .sqrt();
                let ends = [(0.0, old_t_omega), (h, t[m])];
                let refined = self.locate_turn(
                    &mut bordered,
                    &mut hb,
                    &mut ws,
                    &x,
                    omega,
                    &prev_t,
                    ends,
                    sc,
                );
                // Fallback: dΩ/ds linear in s between both tangents.
                Some(refined.unwrap_or_else(|| {
                    let s_star = h * old_t_omega / (old_t_omega - t[m]);
                    omega + sc.so * old_t_omega * s_star / 2.0
                }))
            } else {
                None
            };
            let passed = (o_new - to) * direction >= 0.0;
            if passed && !turn {
                // Land exactly on `to`: correct the interpolated point with Ω fixed.
                let a = (to - omega) / (o_new - omega);
                let xl: Vec<f64> = (0..m).map(|i| x[i] + a * (x_new[i] - x[i])).collect();
                let mut xc = xl.clone();
                let mut oc = to;
                let land = Target {
                    xp: &xl,
                    op: to,
                    row: &land_row,
                };
                if let Some((_, r)) =
                    self.correct(&mut bordered, &mut hb, &mut ws, &mut xc, &mut oc, &land, sc)
                {
                    x_new.copy_from_slice(&xc);
                    o_new = to;
                    rel = r;
                }
            }
            // Rescale x to the new point's size, keeping the tangent's direction.
            let sx_new = rms(&x_new);
            for v in t[..m].iter_mut() {
                *v *= sc.sx / sx_new;
            }
            let norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
            t.iter_mut().for_each(|v| *v /= norm);
            sc.sx = sx_new;
            x.copy_from_slice(&x_new);
            omega = o_new;
            if let Some(reason) =
                self.push(&mut branch, model, &hb, &x, omega, rel, turn, turn_omega)
            {
                branch.stop = BranchStop::StabilityFailed { omega, reason };
                break;
            }
            progress(((omega - from) / (to - from)).clamp(0.0, 1.0));
            if (omega - to) * direction >= 0.0 {
                branch.stop = BranchStop::Reached;
                break;
            }
            if iterations <= 2 {
                step = (step * 1.5).min(self.max_step);
            } else if iterations >= 5 {
                step *= 0.7;
            }
        }
        super::point::classify_turns(&mut branch);
        if branch.points.len() >= self.max_points && branch.stop == BranchStop::Reached {
            let last = branch.points.last().map_or(from, |p| p.omega);
            if (last - to) * direction < 0.0 {
                branch.stop = BranchStop::MaxPoints;
            }
        }
        Ok(branch)
    }

    /// Newton on the bordered system towards `target`, from `(x, Ω)`; on success the number
    /// of iterations and the relative residual (the matrix is then factored at the result).
    #[allow(clippy::too_many_arguments)]
    fn correct(
        &self,
        b: &mut Bordered,
        hb: &mut HarmonicBalance,
        ws: &mut Workspace,
        x: &mut [f64],
        o: &mut f64,
        target: &Target,
        sc: Scales,
    ) -> Option<(usize, f64)> {
        let m = x.len();
        for it in 0..=self.max_corrector {
            if !(*o > 0.0 && o.is_finite()) {
                return None;
            }
            let rel = match b.factor(hb, ws, x, *o, target.row, sc.sx, sc.so, sc.ext) {
                Ok(Some(rel)) => rel,
                Ok(None) | Err(_) => return None,
            };
            if rel <= self.tolerance {
                return Some((it, rel));
            }
            if it == self.max_corrector {
                return None;
            }
            // δ from [R; tᵀ(y - y_p)].
            let mut g = 0.0;
            for i in 0..m {
                g += target.row[i] * (x[i] - target.xp[i]) / sc.sx;
                b.rhs[i] = -b.r[i];
            }
            g += target.row[m] * (*o - target.op) / sc.so;
            b.rhs[m] = -g;
            lu::solve_in_place(&b.big, &b.perm, &mut b.rhs);
            for i in 0..m {
                x[i] += b.rhs[i] * sc.sx;
            }
            *o += b.rhs[m] * sc.so;
        }
        None
    }

    /// The Ω of the turning point between the point `(x, Ω)` (arclength 0, tangent `t0`) and
    /// the next one: the secant method on the tangent's Ω component `t_Ω(s)` along the
    /// predictor line `s ↦ (x, Ω) + s t0`, each `s` corrected onto the branch (hyperplane
    /// normal `t0`). Stops when `|t_Ω| < 1e-12` or the bracket is below 1e-12 of the step.
    #[allow(clippy::too_many_arguments)]
    fn locate_turn(
        &self,
        b: &mut Bordered,
        hb: &mut HarmonicBalance,
        ws: &mut Workspace,
        x: &[f64],
        omega: f64,
        t0: &[f64],
        ends: [(f64, f64); 2],
        sc: Scales,
    ) -> Option<f64> {
        let m = x.len();
        let [(mut s0, mut f0), (mut s1, mut f1)] = ends;
        let (mut xp, mut xc, mut tt) = (vec![0.0; m], vec![0.0; m], vec![0.0; m + 1]);
        let mut best = None;
        for _ in 0..30 {
            if f1 == f0 {
                break;
            }
            let s = s1 - f1 * (s1 - s0) / (f1 - f0);
            if !s.is_finite() {
                break;
            }
            let op = sc.predict(x, omega, t0, s, &mut xp);
            xc.copy_from_slice(&xp);
            let mut oc = op;
            let target = Target {
                xp: &xp,
                op,
                row: t0,
            };
            self.correct(b, hb, ws, &mut xc, &mut oc, &target, sc)?;
            self.tangent(b, &mut tt);
            best = Some(oc);
            if tt[m].abs() < 1e-12 || (s - s1).abs() < 1e-12 * ends[1].0 {
                break;
            }
            (s0, f0, s1, f1) = (s1, f1, s, tt[m]);
        }
        best
    }

    /// `t ← normalised solution of [[R_x s_x, R_Ω s_Ω], [t_oldᵀ]] t = (0, 1)` (factored).
    fn tangent(&self, b: &mut Bordered, t: &mut [f64]) {
        let m = b.layout.len();
        b.rhs.fill(0.0);
        b.rhs[m] = 1.0;
        lu::solve_in_place(&b.big, &b.perm, &mut b.rhs);
        let norm = b.rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
        for (ti, v) in t.iter_mut().zip(&b.rhs) {
            *ti = v / norm;
        }
    }

    /// Appends the point `x` at `omega`; `Some(reason)` if its stability failed.
    #[allow(clippy::too_many_arguments)]
    fn push(
        &self,
        branch: &mut Branch,
        model: &Model,
        hb: &HarmonicBalance,
        x: &[f64],
        omega: f64,
        residual: f64,
        turn: bool,
        turn_omega: Option<f64>,
    ) -> Option<String> {
        let mut harmonics = vec![Complex64::default(); hb.len()];
        hb.layout().unpack(x, &mut harmonics);
        let basis = match HarmonicBasis::new(omega, hb.basis().harmonics())
            .and_then(|b| b.with_samples(hb.basis().samples()))
        {
            Ok(b) => b,
            Err(e) => return Some(e.to_string()),
        };
        self.push_point(
            branch,
            model,
            NewPoint {
                basis,
                harmonics,
                parameter: omega,
                residual,
                turn,
                turn_omega,
            },
        )
    }
}
