//! Good Broyden on `R(x) = 0` with the inverse updated by Sherman–Morrison.
//!
//! `dx = -B R(x)`, `x ← x + α dx` (short backtracking), then with `s = Δx`, `y = ΔR`:
//! `B ← B + (s - B y) sᵀ B / (sᵀ B y)`, `O(m²)` per step instead of an `O(m³)` factorisation.
//! `B⁻¹` starts as the exact AFT Jacobian or the block-diagonal dynamic stiffness `Z`; it is
//! rebuilt from the exact Jacobian when the line search fails or the residual stalls.

use super::lu;
use super::problem::HbProblem;
use super::run::{
    armijo, check_dense, check_tolerance, initial_x, nonfinite, run, HbSolver, HbState, Limits,
    Progress,
};
use crate::error::Result;
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::{Solution, Termination};
use argmin::core::{Problem, Solver, KV};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::time::Duration;

/// Which matrix Broyden's inverse starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialJacobian {
    /// The exact AFT Jacobian at the initial guess.
    Exact,
    /// The block-diagonal dynamic stiffness `Z` (no AFT derivative needed).
    DynamicStiffness,
}

/// Options of Broyden's method.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Broyden {
    /// Relative residual tolerance, in [0, 1). Default 1e-10.
    pub tolerance: f64,
    /// Maximum steps. Default 200.
    pub max_iterations: usize,
    /// Initial Jacobian. Default [`InitialJacobian::Exact`].
    pub initial_jacobian: InitialJacobian,
    /// Restart from the exact Jacobian after this many steps that reduce the residual by less
    /// than 10 %. Default 3.
    pub stall_steps: usize,
    /// Wall-time limit, if any. Default none.
    pub timeout: Option<Duration>,
}

impl Default for Broyden {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 200,
            initial_jacobian: InitialJacobian::Exact,
            stall_steps: 3,
            timeout: None,
        }
    }
}

impl Broyden {
    /// Defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the relative residual tolerance, in [0, 1).
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self> {
        check_tolerance("broyden", tolerance)?;
        self.tolerance = tolerance;
        Ok(self)
    }

    /// Sets the maximum number of steps.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// Sets the initial Jacobian.
    pub fn with_initial_jacobian(mut self, initial: InitialJacobian) -> Self {
        self.initial_jacobian = initial;
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
        check_tolerance("broyden", self.tolerance)?;
        check_dense("broyden", hb)?;
        let x0 = initial_x(hb, initial, true)?;
        let limits = Limits {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            timeout: self.timeout,
        };
        run(hb, ws, BroydenSolver::new(*self, x0), limits)
    }
}

/// Broyden as an argmin [`Solver`].
#[derive(Debug, Clone)]
pub struct BroydenSolver {
    options: Broyden,
    r: Vec<f64>,
    dx: Vec<f64>,
    /// Approximate inverse Jacobian B.
    inverse: DMatrix<f64>,
    /// Scratch for an exact Jacobian and its LU.
    jac: DMatrix<f64>,
    perm: Vec<usize>,
    x_trial: Vec<f64>,
    r_trial: Vec<f64>,
    y: Vec<f64>,
    by: Vec<f64>,
    sb: Vec<f64>,
    rel: f64,
    stalled: usize,
    fresh: bool,
    progress: Progress,
}

impl BroydenSolver {
    /// A solver starting at `x0` (real layout).
    pub fn new(options: Broyden, x0: Vec<f64>) -> Self {
        let m = x0.len();
        Self {
            options,
            r: vec![0.0; m],
            dx: vec![0.0; m],
            inverse: DMatrix::zeros(m, m),
            jac: DMatrix::zeros(m, m),
            perm: vec![0; m],
            x_trial: vec![0.0; m],
            r_trial: vec![0.0; m],
            y: vec![0.0; m],
            by: vec![0.0; m],
            sb: vec![0.0; m],
            rel: f64::INFINITY,
            stalled: 0,
            fresh: false,
            progress: Progress::new(x0, options.max_iterations),
        }
    }

    /// `B ← J⁻¹` with `J` the exact Jacobian at the current iterate (or `Z`); also refreshes `r`.
    fn reset_inverse(&mut self, p: &HbProblem, exact: bool) -> Option<Termination> {
        let rel = if exact {
            p.residual(&self.progress.x, &mut self.r, Some(&mut self.jac))
        } else {
            p.dynamic_stiffness_into(&mut self.jac);
            p.residual(&self.progress.x, &mut self.r, None)
        };
        match rel {
            Ok(rel) if rel.is_finite() => self.rel = rel,
            Ok(_) => return Some(nonfinite("residual")),
            Err(e) => return Some(Termination::from_error(&e)),
        }
        p.count_factorization();
        if !lu::factor_in_place(&mut self.jac, &mut self.perm) {
            return Some(Termination::SingularJacobian);
        }
        let m = self.r.len();
        self.inverse.fill(0.0);
        for j in 0..m {
            let col = &mut self.inverse.as_mut_slice()[j * m..(j + 1) * m];
            col[j] = 1.0;
            lu::solve_in_place(&self.jac, &self.perm, col);
        }
        if !self.inverse.iter().all(|v| v.is_finite()) {
            return Some(Termination::SingularJacobian);
        }
        self.fresh = exact;
        self.stalled = 0;
        None
    }

    /// One step `x + α B(-r)` with up to 4 halvings; `Some(rel)` if accepted.
    fn try_step(&mut self, p: &HbProblem) -> Option<f64> {
        let m = self.r.len();
        self.dx.fill(0.0);
        for j in 0..m {
            let rj = self.r[j];
            if rj != 0.0 {
                let col = &self.inverse.as_slice()[j * m..(j + 1) * m];
                for (d, b) in self.dx.iter_mut().zip(col) {
                    *d -= b * rj;
                }
            }
        }
        armijo(
            p,
            &self.progress.x,
            &self.dx,
            self.rel,
            4,
            &mut self.x_trial,
            &mut self.r_trial,
        )
    }
}

impl HbSolver for BroydenSolver {
    fn progress(&self) -> &Progress {
        &self.progress
    }
}

impl<'a, 'm> Solver<HbProblem<'a, 'm>, HbState> for BroydenSolver {
    fn name(&self) -> &str {
        "broyden"
    }

    fn init(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        let exact = self.options.initial_jacobian == InitialJacobian::Exact;
        let failed = self.reset_inverse(p, exact);
        if self.rel.is_finite() {
            self.progress.record(self.rel);
        }
        if let Some(t) = failed {
            return Ok((self.progress.stop(state, t), None));
        }
        Ok((state.cost(self.rel), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        p.count_iteration();
        let mut accepted = self.try_step(p);
        if accepted.is_none() && !self.fresh {
            // Restart from the exact Jacobian and try once more.
            if let Some(t) = self.reset_inverse(p, true) {
                return Ok((self.progress.stop(state, t), None));
            }
            accepted = self.try_step(p);
        }
        let Some(rel) = accepted else {
            return Ok((
                self.progress.stop(state, Termination::LineSearchFailed),
                None,
            ));
        };
        // s = x_trial - x (kept in dx), y = r_trial - r.
        let m = self.r.len();
        for i in 0..m {
            self.dx[i] = self.x_trial[i] - self.progress.x[i];
            self.y[i] = self.r_trial[i] - self.r[i];
        }
        std::mem::swap(&mut self.progress.x, &mut self.x_trial);
        std::mem::swap(&mut self.r, &mut self.r_trial);
        self.stalled = if rel > 0.9 * self.rel {
            self.stalled + 1
        } else {
            0
        };
        self.rel = rel;
        self.fresh = false;
        self.progress.record(rel);
        // B y and sᵀ B.
        let b = self.inverse.as_slice();
        self.by.fill(0.0);
        for j in 0..m {
            let yj = self.y[j];
            let col = &b[j * m..(j + 1) * m];
            for (o, v) in self.by.iter_mut().zip(col) {
                *o += v * yj;
            }
            self.sb[j] = col.iter().zip(&self.dx).map(|(v, s)| v * s).sum();
        }
        let denom: f64 = self.dx.iter().zip(&self.by).map(|(s, v)| s * v).sum();
        let s_norm = self.dx.iter().map(|v| v * v).sum::<f64>().sqrt();
        let by_norm = self.by.iter().map(|v| v * v).sum::<f64>().sqrt();
        if denom.abs() > 1e-14 * s_norm * by_norm && self.stalled < self.options.stall_steps {
            let b = self.inverse.as_mut_slice();
            for j in 0..m {
                let c = self.sb[j] / denom;
                if c != 0.0 {
                    for i in 0..m {
                        b[j * m + i] += (self.dx[i] - self.by[i]) * c;
                    }
                }
            }
        } else if let Some(t) = self.reset_inverse(p, true) {
            return Ok((self.progress.stop(state, t), None));
        }
        Ok((state.cost(rel), None))
    }
}
