//! Anderson acceleration of the paper's fixed-point map `G(x) = Z⁻¹ (F_ext - F_rest(x))`.
//!
//! With `f_k = G(x_k) - x_k` and the last `m` differences `ΔF = [Δf]`, `ΔX = [Δx]`, the
//! coefficients `c = argmin ‖f_k - ΔF c‖` (normal equations with a small Tikhonov term) give
//! `x_{k+1} = x_k - ΔX c + β (f_k - ΔF c)`, β = 1 - γ (Walker & Ni 2011, "Anderson acceleration
//! for fixed-point iterations"). It keeps the cheap per-harmonic solves and needs no Jacobian;
//! the history is cleared when the residual jumps.

use super::coarse::CoarseBlock;
use super::problem::HbProblem;
use super::run::{
    check_tolerance, initial_x, run_with_coarse, HbSolver, HbState, Limits, Progress,
};
use crate::error::{Error, Result};
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::{Solution, Termination};
use argmin::core::{Problem, Solver, KV};
use num_complex::Complex64;
use std::time::Duration;

/// Options of Anderson acceleration.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Anderson {
    /// History depth m (1..=20). Default 5.
    pub depth: usize,
    /// Relaxation γ ∈ [0, 1) of the underlying fixed point (β = 1 - γ). Default 0.
    pub gamma: f64,
    /// Relative residual tolerance, in [0, 1). Default 1e-10.
    pub tolerance: f64,
    /// Maximum iterations. Default 200.
    pub max_iterations: usize,
    /// Stop as diverged once the residual exceeds this factor times its best value. Default 1e3.
    pub divergence_factor: f64,
    /// Wall-time limit, if any. Default none.
    pub timeout: Option<Duration>,
    /// Harmonics `H_c` stepped with Newton's Jacobian (the two-level map of
    /// [`coarse`](super::coarse)); the paper's per-harmonic map if none or `>= H`. Default none.
    #[serde(default)]
    pub coarse_harmonics: Option<usize>,
}

impl Default for Anderson {
    fn default() -> Self {
        Self {
            depth: 5,
            gamma: 0.0,
            divergence_factor: 1e3,
            tolerance: 1e-10,
            max_iterations: 200,
            timeout: None,
            coarse_harmonics: None,
        }
    }
}

impl Anderson {
    /// Defaults: depth 5, γ = 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the depth m (1..=20).
    pub fn with_depth(mut self, depth: usize) -> Result<Self> {
        if !(1..=20).contains(&depth) {
            return Err(Error::invalid(
                "anderson",
                "depth",
                depth as f64,
                "in 1..=20",
            ));
        }
        self.depth = depth;
        Ok(self)
    }

    /// Sets γ ∈ [0, 1).
    pub fn with_gamma(mut self, gamma: f64) -> Result<Self> {
        if !(gamma.is_finite() && (0.0..1.0).contains(&gamma)) {
            return Err(Error::invalid("anderson", "gamma", gamma, "in [0, 1)"));
        }
        self.gamma = gamma;
        Ok(self)
    }

    /// Sets the relative residual tolerance, in [0, 1).
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self> {
        check_tolerance("anderson", tolerance)?;
        self.tolerance = tolerance;
        Ok(self)
    }

    /// Sets the maximum number of iterations.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// Steps the harmonics `0..=hc` with Newton's Jacobian of the basis with `hc` harmonics
    /// (factored once, at the start): the two-level map that makes large H cost a few dozen
    /// FFTs. Without a warm start the solve starts from Newton's solution on that basis.
    ///
    /// ```
    /// use hbal::catalog::TwoShaft;
    /// use hbal::{Anderson, HarmonicBalance, HarmonicBasis};
    /// let shaft = TwoShaft::new(6000.0);
    /// let model = shaft.model()?;
    /// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(shaft.mesh_omega(), 512)?)?;
    /// let sol = Anderson::new().with_coarse_harmonics(32).solve(&hb, &mut hb.workspace())?;
    /// assert!(sol.is_converged() && sol.stats.iterations < 40);
    /// # Ok::<(), hbal::Error>(())
    /// ```
    pub fn with_coarse_harmonics(mut self, hc: usize) -> Self {
        self.coarse_harmonics = Some(hc);
        self
    }

    /// Solves from the linear frequency-domain solution (the paper's first iterate).
    pub fn solve(&self, hb: &HarmonicBalance, ws: &mut Workspace) -> Result<Solution> {
        self.solve_from_option(hb, None, ws)
    }

    /// Solves from a warm start (harmonic-major, `(H+1)·n`).
    pub fn solve_from(
        &self,
        hb: &HarmonicBalance,
        initial: &[Complex64],
        ws: &mut Workspace,
    ) -> Result<Solution> {
        self.solve_from_option(hb, Some(initial), ws)
    }

    pub(crate) fn solve_from_option(
        &self,
        hb: &HarmonicBalance,
        initial: Option<&[Complex64]>,
        ws: &mut Workspace,
    ) -> Result<Solution> {
        self.with_depth(self.depth)?.with_gamma(self.gamma)?;
        check_tolerance("anderson", self.tolerance)?;
        let limits = Limits {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            timeout: self.timeout,
        };
        // A full-DOF warm start of a condensed problem, on its coordinates.
        let projected = initial.and_then(|q| hb.unknowns_of(q));
        let initial = projected.as_deref().or(initial);
        let coarse = match self.coarse_harmonics {
            Some(hc) if hc < hb.basis().harmonics() => CoarseBlock::build(hb, hc, initial)?,
            _ => None,
        };
        let x0 = match (&coarse, initial) {
            (Some((_, start)), None) => initial_x(hb, Some(start), false)?,
            _ => initial_x(hb, initial, true)?,
        };
        let solver = AndersonSolver::new(*self, x0);
        run_with_coarse(hb, ws, solver, limits, coarse.as_ref().map(|c| &c.0))
    }
}

/// Anderson acceleration as an argmin [`Solver`]; all buffers preallocated.
#[derive(Debug, Clone)]
pub struct AndersonSolver {
    options: Anderson,
    g: Vec<f64>,
    f: Vec<f64>,
    f_prev: Vec<f64>,
    x_prev: Vec<f64>,
    /// Columns of ΔF and ΔX, ring buffers of `depth` columns.
    df: Vec<Vec<f64>>,
    dx: Vec<Vec<f64>>,
    stored: usize,
    next: usize,
    normal: Vec<f64>,
    coef: Vec<f64>,
    best: f64,
    progress: Progress,
}

impl AndersonSolver {
    /// A solver starting at `x0` (real layout).
    pub fn new(options: Anderson, x0: Vec<f64>) -> Self {
        let (m, d) = (x0.len(), options.depth);
        Self {
            options,
            g: vec![0.0; m],
            f: vec![0.0; m],
            f_prev: vec![0.0; m],
            x_prev: vec![0.0; m],
            df: vec![vec![0.0; m]; d],
            dx: vec![vec![0.0; m]; d],
            stored: 0,
            next: 0,
            normal: vec![0.0; d * d],
            coef: vec![0.0; d],
            best: f64::INFINITY,
            progress: Progress::new(x0, options.max_iterations),
        }
    }

    /// Evaluates `G(x)` and `f = G(x) - x`; `Err` holds the termination.
    fn evaluate(&mut self, p: &HbProblem) -> std::result::Result<f64, Termination> {
        match p.fixed_point_map(&self.progress.x, &mut self.g) {
            Ok(rel) if rel.is_finite() && self.g.iter().all(|v| v.is_finite()) => {
                for ((f, g), x) in self.f.iter_mut().zip(&self.g).zip(&self.progress.x) {
                    *f = g - x;
                }
                Ok(rel)
            }
            Ok(_) => Err(Termination::NonFinite {
                what: "residual or linear solve".into(),
            }),
            Err(e) => Err(Termination::from_error(&e)),
        }
    }

    /// Solves the normal equations `(ΔFᵀΔF + λ I) c = ΔFᵀ f` by Gaussian elimination in place.
    fn coefficients(&mut self) -> bool {
        let k = self.stored;
        for i in 0..k {
            for j in 0..=i {
                let v: f64 = self.df[i].iter().zip(&self.df[j]).map(|(a, b)| a * b).sum();
                self.normal[i * k + j] = v;
                self.normal[j * k + i] = v;
            }
            self.coef[i] = self.df[i].iter().zip(&self.f).map(|(a, b)| a * b).sum();
        }
        let trace: f64 = (0..k).map(|i| self.normal[i * k + i]).sum();
        let lambda = 1e-12 * trace.max(f64::MIN_POSITIVE);
        for i in 0..k {
            self.normal[i * k + i] += lambda;
        }
        // Symmetric positive definite: elimination without pivoting.
        for c in 0..k {
            let pivot = self.normal[c * k + c];
            if !(pivot > 0.0 && pivot.is_finite()) {
                return false;
            }
            for r in c + 1..k {
                let l = self.normal[r * k + c] / pivot;
                for j in c..k {
                    self.normal[r * k + j] -= l * self.normal[c * k + j];
                }
                self.coef[r] -= l * self.coef[c];
            }
        }
        for c in (0..k).rev() {
            let mut v = self.coef[c];
            for j in c + 1..k {
                v -= self.normal[c * k + j] * self.coef[j];
            }
            self.coef[c] = v / self.normal[c * k + c];
        }
        self.coef[..k].iter().all(|v| v.is_finite())
    }
}

impl HbSolver for AndersonSolver {
    fn progress(&self) -> &Progress {
        &self.progress
    }
}

impl<'a, 'm> Solver<HbProblem<'a, 'm>, HbState> for AndersonSolver {
    fn name(&self) -> &str {
        "anderson"
    }

    fn init(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        match self.evaluate(p) {
            Ok(rel) => {
                self.best = rel;
                self.progress.record(rel);
                Ok((state.cost(rel), None))
            }
            Err(t) => Ok((self.progress.stop(state, t), None)),
        }
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        let beta = 1.0 - self.options.gamma;
        let m = self.f.len();
        // Step with the current history.
        let use_history = self.stored > 0 && self.coefficients();
        self.x_prev.copy_from_slice(&self.progress.x);
        self.f_prev.copy_from_slice(&self.f);
        for i in 0..m {
            let (mut xi, mut fi) = (self.progress.x[i], self.f[i]);
            if use_history {
                for c in 0..self.stored {
                    xi -= self.dx[c][i] * self.coef[c];
                    fi -= self.df[c][i] * self.coef[c];
                }
            }
            self.progress.x[i] = xi + beta * fi;
        }
        p.count_iteration();
        let rel = match self.evaluate(p) {
            Ok(rel) => rel,
            Err(t) => {
                self.progress.x.copy_from_slice(&self.x_prev);
                return Ok((self.progress.stop(state, t), None));
            }
        };
        self.progress.record(rel);
        if rel > self.options.divergence_factor * self.best {
            self.progress.x.copy_from_slice(&self.x_prev);
            return Ok((self.progress.stop(state, Termination::Diverged), None));
        }
        if rel > 10.0 * self.best {
            // A bad extrapolation: forget the history (the iterate stays).
            self.stored = 0;
            self.next = 0;
        } else {
            let c = self.next;
            for i in 0..m {
                self.df[c][i] = self.f[i] - self.f_prev[i];
                self.dx[c][i] = self.progress.x[i] - self.x_prev[i];
            }
            self.next = (self.next + 1) % self.options.depth;
            self.stored = (self.stored + 1).min(self.options.depth);
        }
        self.best = self.best.min(rel);
        Ok((state.cost(rel), None))
    }
}
