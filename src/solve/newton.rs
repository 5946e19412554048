//! Newton's method on `R(x) = 0` with the exact AFT Jacobian and a backtracking line search.
//!
//! `J(x) dx = -R(x)` by dense LU (factored in the Jacobian's own buffer), then
//! `x ← x + α dx` with the largest `α ∈ {1, ½, ¼, ...}` that satisfies the Armijo condition
//! `‖R(x + α dx)‖ <= (1 - 10⁻⁴ α) ‖R(x)‖`: robust on non-smooth contact, where a full step can
//! overshoot a contact edge. Trial points are evaluated without the Jacobian; the accepted one
//! gets it (fused with its residual) only if another step follows. Where every law is linear
//! in the state the Jacobian does not depend on x: it is factored once and the later steps
//! (which take up the tail correction the Jacobian leaves out) reuse the factors.

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

/// Options of Newton's method.
///
/// ```
/// use hbal::catalog::GearBacklash;
/// use hbal::{HarmonicBalance, HarmonicBasis, Newton};
/// // The gear pair with backlash at W = 0.5: the paper's fixed point stalls here (harmonic 2
/// // sits on the natural frequency); Newton converges in a few steps.
/// let model = GearBacklash::default().model()?;
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.5, 16)?)?;
/// let sol = Newton::new().solve(&hb, &mut hb.workspace())?;
/// assert!(sol.is_converged() && sol.stats.iterations <= 6);
/// # Ok::<(), hbal::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Newton {
    /// Relative residual tolerance, in [0, 1). Default 1e-10.
    pub tolerance: f64,
    /// Maximum Newton steps. Default 50.
    pub max_iterations: usize,
    /// Maximum step halvings per line search. Default 30.
    pub max_halvings: usize,
    /// Wall-time limit, if any. Default none.
    pub timeout: Option<Duration>,
}

impl Default for Newton {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 50,
            max_halvings: 30,
            timeout: None,
        }
    }
}

impl Newton {
    /// Defaults: tolerance 1e-10, 50 steps.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the relative residual tolerance, in [0, 1).
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self> {
        check_tolerance("newton", tolerance)?;
        self.tolerance = tolerance;
        Ok(self)
    }

    /// Sets the maximum number of Newton steps.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
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
        check_tolerance("newton", self.tolerance)?;
        check_dense("newton", hb)?;
        let x0 = initial_x(hb, initial, true)?;
        let limits = Limits {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            timeout: self.timeout,
        };
        run(hb, ws, NewtonSolver::new(*self, x0), limits)
    }
}

/// Newton as an argmin [`Solver`]; one Jacobian buffer, reused for its LU factors.
#[derive(Debug, Clone)]
pub struct NewtonSolver {
    options: Newton,
    r: Vec<f64>,
    dx: Vec<f64>,
    jac: DMatrix<f64>,
    perm: Vec<usize>,
    x_trial: Vec<f64>,
    r_trial: Vec<f64>,
    rel: f64,
    /// `jac` holds LU factors that stay valid (a Jacobian that does not depend on `x`).
    factored: bool,
    progress: Progress,
}

impl NewtonSolver {
    /// A solver starting at `x0` (real layout).
    pub fn new(options: Newton, x0: Vec<f64>) -> Self {
        let m = x0.len();
        Self {
            options,
            r: vec![0.0; m],
            dx: vec![0.0; m],
            jac: DMatrix::zeros(m, m),
            perm: vec![0; m],
            x_trial: vec![0.0; m],
            r_trial: vec![0.0; m],
            rel: f64::INFINITY,
            factored: false,
            progress: Progress::new(x0, options.max_iterations),
        }
    }
}

impl HbSolver for NewtonSolver {
    fn progress(&self) -> &Progress {
        &self.progress
    }
}

impl<'a, 'm> Solver<HbProblem<'a, 'm>, HbState> for NewtonSolver {
    fn name(&self) -> &str {
        "newton"
    }

    fn init(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        self.factored = false;
        match p.residual(&self.progress.x, &mut self.r, Some(&mut self.jac)) {
            Ok(rel) if rel.is_finite() => {
                self.rel = rel;
                self.progress.record(rel);
                Ok((state.cost(rel), None))
            }
            Ok(_) => Ok((self.progress.stop(state, nonfinite("residual")), None)),
            Err(e) => Ok((self.progress.stop(state, Termination::from_error(&e)), None)),
        }
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        // Every law linear in the state: the Jacobian is the same at every x, factored once
        // (the steps after the first take up what it leaves out: the tail correction).
        let constant = p.hb().is_linear_in_state();
        if !(constant && self.factored) {
            p.count_factorization();
            if !lu::factor_in_place(&mut self.jac, &mut self.perm) {
                return Ok((
                    self.progress.stop(state, Termination::SingularJacobian),
                    None,
                ));
            }
            self.factored = true;
        }
        for (d, r) in self.dx.iter_mut().zip(&self.r) {
            *d = -r;
        }
        lu::solve_in_place(&self.jac, &self.perm, &mut self.dx);
        if !self.dx.iter().all(|v| v.is_finite()) {
            return Ok((
                self.progress.stop(state, Termination::SingularJacobian),
                None,
            ));
        }
        p.count_iteration();
        let Some(rel) = armijo(
            p,
            &self.progress.x,
            &self.dx,
            self.rel,
            self.options.max_halvings,
            &mut self.x_trial,
            &mut self.r_trial,
        ) else {
            return Ok((
                self.progress.stop(state, Termination::LineSearchFailed),
                None,
            ));
        };
        std::mem::swap(&mut self.progress.x, &mut self.x_trial);
        std::mem::swap(&mut self.r, &mut self.r_trial);
        self.rel = rel;
        self.progress.record(rel);
        // The Jacobian for the next step, unless this one is the last.
        if rel > self.options.tolerance && !constant {
            if let Err(e) = p.residual(&self.progress.x, &mut self.r, Some(&mut self.jac)) {
                return Ok((self.progress.stop(state, Termination::from_error(&e)), None));
            }
        }
        Ok((state.cost(rel), None))
    }
}
