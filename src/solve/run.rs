//! Running a solver with argmin's `Executor` and turning its state into a [`Solution`].

use super::coarse::CoarseBlock;
use super::problem::HbProblem;
use crate::error::{Error, Result};
use crate::residual::{HarmonicBalance, Workspace};
use crate::solution::{Solution, Termination};
use argmin::core::{Executor, IterState, Solver, State, TerminationReason};
use num_complex::Complex64;
use std::time::{Duration, Instant};

/// argmin's iteration state for hbal: the cost is the relative residual. The iterate itself
/// stays in the solver's buffers (argmin would clone a parameter vector on every improvement).
pub type HbState = IterState<Vec<f64>, (), (), (), (), f64>;

/// What every hbal solver records for its [`Solution`].
#[derive(Debug, Clone, Default)]
pub struct Progress {
    /// The last iterate with a finite residual (real layout).
    pub x: Vec<f64>,
    /// Relative residual of every iterate, starting with the initial guess.
    pub history: Vec<f64>,
    /// Seconds since the start of the solve at which each history entry was recorded.
    pub seconds: Vec<f64>,
    /// A stop decided by the solver itself (divergence, singular matrix, ...).
    pub termination: Option<Termination>,
    start: Option<Instant>,
}

impl Progress {
    pub(crate) fn new(x0: Vec<f64>, max_iterations: usize) -> Self {
        // Room for the usual solve, so that iterating does not allocate; a larger (or absurd)
        // iteration limit grows the history as needed instead of reserving it all.
        let capacity = max_iterations.min(PREALLOCATED_ITERATIONS) + 2;
        Self {
            x: x0,
            history: Vec::with_capacity(capacity),
            seconds: Vec::with_capacity(capacity),
            termination: None,
            start: Some(Instant::now()),
        }
    }

    /// Records the relative residual of a new iterate and when it was reached.
    pub(crate) fn record(&mut self, residual: f64) {
        self.history.push(residual);
        let t = self.start.map_or(0.0, |s| s.elapsed().as_secs_f64());
        self.seconds.push(t);
    }

    /// Records a solver-decided stop; argmin sees it as `SolverExit`.
    pub(crate) fn stop(&mut self, state: HbState, why: Termination) -> HbState {
        self.termination = Some(why);
        state.terminate_with(TerminationReason::SolverExit(String::new()))
    }
}

/// Iterations whose history is reserved before a solve starts.
const PREALLOCATED_ITERATIONS: usize = 1 << 16;

/// A solver that exposes its [`Progress`].
pub trait HbSolver {
    /// The recorded progress.
    fn progress(&self) -> &Progress;
}

/// Common stopping limits.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    pub tolerance: f64,
    pub max_iterations: usize,
    pub timeout: Option<Duration>,
}

/// Largest number of real unknowns for the dense Jacobian of Newton and Broyden
/// (8192² doubles = 512 MiB).
pub const MAX_DENSE_UNKNOWNS: usize = 8192;

/// Refuses a dense Jacobian that would not fit in memory, with advice.
pub(crate) fn check_dense(context: &str, hb: &HarmonicBalance) -> Result<()> {
    let m = hb.layout().len();
    if m > MAX_DENSE_UNKNOWNS {
        return Err(Error::invalid(
            context,
            "unknowns n(2H+1)",
            m as f64,
            format!(
                "<= {MAX_DENSE_UNKNOWNS} for a dense Jacobian ({:.1} GiB here): use fixed_point or anderson, or fewer harmonics",
                (m * m * 8) as f64 / (1u64 << 30) as f64
            ),
        ));
    }
    Ok(())
}

/// Checks a relative tolerance.
pub(crate) fn check_tolerance(context: &str, tolerance: f64) -> Result<()> {
    if tolerance.is_finite() && (0.0..1.0).contains(&tolerance) {
        Ok(())
    } else {
        Err(Error::invalid(context, "tolerance", tolerance, "in [0, 1)"))
    }
}

/// The initial real unknowns: a warm start (checked), or else the linear frequency-domain
/// solution `Z_k⁻¹ F_split,k` (the paper's step 0) if `linear` is set, or zero.
pub(crate) fn initial_x(
    hb: &HarmonicBalance,
    initial: Option<&[Complex64]>,
    linear: bool,
) -> Result<Vec<f64>> {
    let layout = hb.layout();
    let mut x = vec![0.0; layout.len()];
    if initial.is_none() && linear {
        let mut q = hb.split_load().to_vec();
        let n = layout.n;
        for k in 0..=layout.h {
            hb.dynamic_stiffness()
                .solve_in_place(k, &mut q[k * n..(k + 1) * n]);
        }
        if let Some(i) = q
            .iter()
            .position(|v| !(v.re.is_finite() && v.im.is_finite()))
        {
            return Err(Error::NonFinite {
                what: format!(
                    "the linear solution at harmonic {} of `{}` (the loads are out of range \
                     for the model)",
                    i / n.max(1),
                    hb.unknown_names()
                        .get(i % n.max(1))
                        .map_or("?", String::as_str)
                ),
            });
        }
        layout.pack(&q, &mut x);
    }
    if let Some(q) = initial {
        // A full-DOF start for a condensed problem is projected onto its coordinates.
        let Some(q) = hb.unknowns_of(q) else {
            return Err(Error::DimensionMismatch {
                context: "initial harmonics".into(),
                expected: format!("{} ((H+1) * n)", hb.len()),
                got: q.len().to_string(),
            });
        };
        let q = &q[..];
        if !q.iter().all(|v| v.re.is_finite() && v.im.is_finite()) {
            return Err(Error::NonFinite {
                what: "initial harmonics".into(),
            });
        }
        layout.pack(q, &mut x);
    }
    Ok(x)
}

/// Runs `solver` on `hb` with argmin's executor and assembles the [`Solution`].
pub(crate) fn run<S>(
    hb: &HarmonicBalance,
    ws: &mut Workspace,
    solver: S,
    limits: Limits,
) -> Result<Solution>
where
    S: for<'a, 'm> Solver<HbProblem<'a, 'm>, HbState> + HbSolver,
{
    run_with_coarse(hb, ws, solver, limits, None)
}

/// [`run`] on the two-level map of `coarse` (if any).
pub(crate) fn run_with_coarse<S>(
    hb: &HarmonicBalance,
    ws: &mut Workspace,
    solver: S,
    limits: Limits,
    coarse: Option<&CoarseBlock>,
) -> Result<Solution>
where
    S: for<'a, 'm> Solver<HbProblem<'a, 'm>, HbState> + HbSolver,
{
    let start = Instant::now();
    let problem = HbProblem::new(hb, ws).with_coarse(coarse);
    problem.reset_stats();
    let mut executor = Executor::new(problem, solver)
        .configure(|state| {
            state
                .max_iters(limits.max_iterations as u64)
                .target_cost(limits.tolerance)
                .counting(false)
        })
        .timer(false);
    if let Some(t) = limits.timeout {
        executor = executor.timeout(t);
    }
    let result = executor.run().map_err(|e| Error::Solver {
        reason: e.to_string(),
    })?;
    let progress = result.solver.progress();
    // argmin checks the iteration limit before the target cost: a solve that meets the
    // tolerance on its last allowed iteration (or starts converged) is converged.
    let met = progress
        .history
        .last()
        .is_some_and(|r| *r <= limits.tolerance)
        && progress.termination.is_none();
    let termination = match result.state.get_termination_reason() {
        _ if met => Termination::Converged,
        Some(TerminationReason::TargetCostReached) | Some(TerminationReason::SolverConverged) => {
            Termination::Converged
        }
        Some(TerminationReason::MaxItersReached) => Termination::MaxIterations,
        Some(TerminationReason::Timeout) => Termination::Timeout,
        Some(TerminationReason::Interrupt) => Termination::Interrupted,
        _ => progress
            .termination
            .clone()
            .unwrap_or(Termination::Interrupted),
    };
    let problem = result
        .problem
        .problem
        .as_ref()
        .ok_or_else(|| Error::Solver {
            reason: "argmin returned no problem".into(),
        })?;
    let mut history = progress.history.clone();
    let mut history_seconds = progress.seconds.clone();
    if history.is_empty() {
        // The start failed before its residual was recorded (its Jacobian, say): the
        // residual alone, or, if that is not finite either, no iterate at all, only where.
        let mut r = vec![0.0; progress.x.len()];
        history.push(problem.residual(&progress.x, &mut r, None)?);
        history_seconds.push(start.elapsed().as_secs_f64());
    }
    let stats = problem.take_stats();
    let mut unknowns = vec![Complex64::default(); hb.len()];
    hb.layout().unpack(&progress.x, &mut unknowns);
    let harmonics = problem.full_harmonics(&unknowns)?;
    let names = hb.model().dof_names();
    if let Some(i) = harmonics
        .iter()
        .position(|v| !(v.re.is_finite() && v.im.is_finite()))
    {
        let n = names.len().max(1);
        return Err(Error::NonFinite {
            what: format!(
                "harmonic {} of DOF `{}` of the last iterate",
                i / n,
                names.get(i % n).map_or("?", String::as_str)
            ),
        });
    }
    Ok(Solution {
        basis: *hb.basis(),
        dofs: hb.model().dof_names().to_vec(),
        harmonics,
        termination,
        history,
        history_seconds,
        stats,
        wall_time: start.elapsed(),
    })
}

/// A non-finite termination naming `what`.
pub(crate) fn nonfinite(what: &str) -> Termination {
    Termination::NonFinite {
        what: what.to_string(),
    }
}

/// Backtracking line search: the largest `α ∈ {1, ½, ¼, …}` (at most `halvings` halvings) with
/// `‖R(x + α dx)‖ <= (1 - 10⁻⁴ α) ‖R(x)‖` (Armijo). Leaves the accepted point in `x_trial`,
/// its residual in `r_trial`, and returns its relative residual.
pub(crate) fn armijo(
    p: &HbProblem,
    x: &[f64],
    dx: &[f64],
    rel: f64,
    halvings: usize,
    x_trial: &mut [f64],
    r_trial: &mut [f64],
) -> Option<f64> {
    let mut alpha = 1.0;
    for _ in 0..=halvings {
        for ((t, xi), d) in x_trial.iter_mut().zip(x).zip(dx) {
            *t = xi + alpha * d;
        }
        if let Ok(r) = p.residual(x_trial, r_trial, None) {
            if r.is_finite() && r <= (1.0 - 1e-4 * alpha) * rel {
                return Some(r);
            }
        }
        alpha *= 0.5;
    }
    None
}
