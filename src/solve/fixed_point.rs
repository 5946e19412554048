//! The paper's iterative linear solver (Bauer et al. 2021, section 3, eq. 5).
//!
//! Starting from `Q = 0` (or a warm start), repeat:
//! 1. evaluate `f_rhs(t) = f(t) - D1(t) q̇(t) - K1(t) q(t)` (and any nonlinearity) in the time
//!    domain and take its harmonics `F_rhs = F_ext - F_rest(Q)` (steps 2a, 2b);
//! 2. solve `Z_k Q'_k = F_rhs,k` for every harmonic with the factored
//!    `Z_k = -(kΩ)² M + i kΩ D0 + K0` (step 2c);
//! 3. relax `Q ← γ Q + (1-γ) Q'` (step 2d; γ = 0 is the undamped iteration);
//! 4. synthesise `q(t)`, `q̇(t)` (step 2e, done inside the next AFT).
//!
//! The first solve from `Q = 0` is the classic linear frequency-domain solution. The residual
//! `R(Q) = Z Q - F_rhs(Q)` of every iterate comes from the same AFT and is checked against the
//! tolerance before the next solve. In the notation of the other solvers this is
//! `x ← x - (1-γ) Z⁻¹ R(x)`: Newton's update with the dynamic stiffness for the Jacobian.

use super::problem::HbProblem;
use super::run::{check_tolerance, initial_x, run, HbSolver, HbState, Limits, Progress};
use crate::error::{Error, Result};
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::{Solution, Termination};
use argmin::core::{Problem, Solver, TerminationReason, TerminationStatus, KV};
use num_complex::Complex64;

/// Options of the paper's fixed-point iteration.
///
/// ```
/// use hbal::{force::CubicSpring, FixedPoint, HarmonicBalance, HarmonicBasis, Model};
/// // Weak Duffing oscillator x'' + 0.1 x' + x + 0.1 x³ = 0.1 cos(2t), away from resonance.
/// let model = Model::builder(&["x"])
///     .mass_diagonal(&[1.0])
///     .damping(nalgebra::DMatrix::from_element(1, 1, 0.1))
///     .element("duffing", &[("x", 1.0)], CubicSpring::new(1.0, 0.1))
///     .load("x", 1, 0.1, 0.0)
///     .build()?;
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(2.0, 7)?)?;
/// let sol = FixedPoint::new().with_tolerance(1e-12)?.solve(&hb, &mut hb.workspace())?;
/// assert!(sol.is_converged());
/// let (a1, _) = sol.cos_sin(0, 1);
/// assert!((a1 + 0.0332).abs() < 1e-3); // close to the linear -0.1/3
/// # Ok::<(), hbal::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FixedPoint {
    /// Relaxation γ ∈ [0, 1): `Q ← γ Q + (1-γ) Q'`. Default 0 (the paper's run).
    pub gamma: f64,
    /// Relative residual tolerance, in [0, 1). Default 1e-10.
    pub tolerance: f64,
    /// Maximum number of linear solves. Default 200.
    pub max_iterations: usize,
    /// Stop as diverged once the residual exceeds this factor times its best value. Default 1e3.
    pub divergence_factor: f64,
}

impl Default for FixedPoint {
    fn default() -> Self {
        Self {
            gamma: 0.0,
            tolerance: 1e-10,
            max_iterations: 200,
            divergence_factor: 1e3,
        }
    }
}

impl FixedPoint {
    /// Defaults: γ = 0, tolerance 1e-10, 200 iterations.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets γ ∈ [0, 1).
    pub fn with_gamma(mut self, gamma: f64) -> Result<Self> {
        if !(gamma.is_finite() && (0.0..1.0).contains(&gamma)) {
            return Err(Error::invalid("fixed point", "gamma", gamma, "in [0, 1)"));
        }
        self.gamma = gamma;
        Ok(self)
    }

    /// Sets the relative residual tolerance, in [0, 1) (0: run to the iteration limit).
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Self> {
        check_tolerance("fixed point", tolerance)?;
        self.tolerance = tolerance;
        Ok(self)
    }

    /// Sets the maximum number of linear solves.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// Solves from `Q = 0`: the first iterate is the linear frequency-domain solution.
    pub fn solve(&self, hb: &HarmonicBalance, ws: &mut Workspace) -> Result<Solution> {
        self.solve_from_option(hb, None, ws)
    }

    /// Solves from the warm start `initial` (harmonic-major, `(H+1)·n`).
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
        self.with_gamma(self.gamma)?
            .with_tolerance(self.tolerance)?;
        if !(self.divergence_factor.is_finite() && self.divergence_factor > 1.0) {
            return Err(Error::invalid(
                "fixed point",
                "divergence_factor",
                self.divergence_factor,
                "finite and > 1",
            ));
        }
        let x0 = initial_x(hb, initial, false)?;
        let solver = FixedPointSolver::new(*self, x0);
        let limits = Limits {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            timeout: None,
        };
        run(hb, ws, solver, limits)
    }
}

/// The fixed point as an argmin [`Solver`].
#[derive(Debug, Clone)]
pub struct FixedPointSolver {
    options: FixedPoint,
    /// `G(x)` of the current iterate.
    g: Vec<f64>,
    /// The previous iterate, restored if the next evaluation fails.
    x_prev: Vec<f64>,
    best: f64,
    progress: Progress,
}

impl FixedPointSolver {
    /// A solver starting at `x0` (real layout).
    pub fn new(options: FixedPoint, x0: Vec<f64>) -> Self {
        let m = x0.len();
        Self {
            options,
            g: vec![0.0; m],
            x_prev: vec![0.0; m],
            best: f64::INFINITY,
            progress: Progress::new(x0, options.max_iterations),
        }
    }

    fn evaluate(&mut self, problem: &HbProblem, state: HbState) -> HbState {
        match problem.fixed_point_map(&self.progress.x, &mut self.g) {
            Ok(rel) if rel.is_finite() && self.g.iter().all(|v| v.is_finite()) => {
                self.progress.record(rel);
                self.best = self.best.min(rel);
                state.cost(rel)
            }
            Ok(_) => self.fail(
                state,
                Termination::NonFinite {
                    what: "residual or linear solve".into(),
                },
            ),
            Err(e) => self.fail(state, Termination::from_error(&e)),
        }
    }

    fn fail(&mut self, state: HbState, why: Termination) -> HbState {
        if !self.progress.history.is_empty() {
            self.progress.x.copy_from_slice(&self.x_prev);
        }
        self.progress.stop(state, why)
    }
}

impl HbSolver for FixedPointSolver {
    fn progress(&self) -> &Progress {
        &self.progress
    }
}

impl<'a, 'm> Solver<HbProblem<'a, 'm>, HbState> for FixedPointSolver {
    fn name(&self) -> &str {
        "fixed point"
    }

    fn init(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        self.x_prev.copy_from_slice(&self.progress.x);
        Ok((self.evaluate(p, state), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<HbProblem<'a, 'm>>,
        state: HbState,
    ) -> std::result::Result<(HbState, Option<KV>), argmin::core::Error> {
        let p = problem.problem.as_ref().expect("problem present");
        let g = self.options.gamma;
        self.x_prev.copy_from_slice(&self.progress.x);
        for (x, gx) in self.progress.x.iter_mut().zip(&self.g) {
            *x = g * *x + (1.0 - g) * gx;
        }
        p.count_iteration();
        Ok((self.evaluate(p, state), None))
    }

    fn terminate(&mut self, state: &HbState) -> TerminationStatus {
        if state.get_cost() > self.options.divergence_factor * self.best {
            self.progress.termination = Some(Termination::Diverged);
            return TerminationStatus::Terminated(TerminationReason::SolverExit(String::new()));
        }
        TerminationStatus::NotTerminated
    }
}
