//! Laws with memory in the time domain: the state is frozen over each integrator step and
//! committed after it, with a restart wherever freezing it was wrong.
//!
//! Over a step `[t_a, t_b]` the right-hand side evaluates every hysteretic law by its step from
//! the state committed at `t_a` (*frozen*). After the step is accepted the state is advanced
//! along the integrator's dense output through sub-points of the step (the *path*); at each of
//! them the frozen force and the path force are compared. As long as they agree (to 1e-11
//! relative) the frozen right-hand side was the true one (for a Jenkins element: stick, or
//! slip that goes on; the switch from stick to slip is the clamp of the force itself, a kink
//! in the state that the error control resolves as for a contact). Where they first differ (a
//! Jenkins slider stopping at a turn of `u̇`), the sub-interval is subdivided again
//! ([`LEVELS`] times [`SUBSTEPS`]), the path state at the last agreeing time is committed and
//! the integrator restarts there. The force then leaves the limit with an error below
//! 1e-11 relative, and the state is the one of the path sampled ~`8⁻⁹` of a step apart
//! around the turn, so the integration keeps the accuracy set by `rtol`.

use super::rhs::Rhs;
use crate::error::{Error, Result};
use crate::force::MAX_STATE;
use differential_equations::prelude::*;
use std::f64::consts::TAU;

/// Sub-points per level.
const SUBSTEPS: usize = 8;
/// Levels of subdivision where the frozen and the path force first differ.
const LEVELS: usize = 9;
/// Relative agreement of the frozen and the path force.
const AGREE: f64 = 1e-11;

type States = Vec<[f64; MAX_STATE]>;

/// The solout: commits the states, restarts at a disagreement, samples and keeps the end.
struct Commit<'a, 'm> {
    rhs: &'a Rhs<'m>,
    t_end: f64,
    times: &'a [f64],
    out: &'a mut [Option<Vec<f64>>],
    next: usize,
    error: &'a mut Option<String>,
    /// Where the integration stopped to restart, and the state there.
    restart: &'a mut Option<(f64, Vec<f64>)>,
}

impl Commit<'_, '_> {
    /// Advances `path` to the state `y` at `t`; `false` if a frozen force differs there.
    fn advance(&self, t: f64, y: &[f64], path: &mut States) -> bool {
        let model = self.rhs.model();
        let (q, v) = y.split_at(model.n_dofs());
        let theta = self.rhs.theta(t);
        let frozen = self.rhs.states.borrow();
        let mut agree = true;
        for ((e, fz), p) in model
            .elements()
            .iter()
            .zip(frozen.iter())
            .zip(path.iter_mut())
        {
            let Some(m) = e.law().memory() else {
                continue;
            };
            let len = m.state_len();
            let (u, du) = (e.gather(q), e.gather(v));
            let mut frozen_state = *fz;
            let f_frozen = m.step(theta, u, du, &mut frozen_state[..len]);
            let f_path = m.step(theta, u, du, &mut p[..len]);
            if (f_frozen - f_path).abs() > AGREE * f_frozen.abs().max(f_path.abs()) {
                agree = false;
            }
        }
        agree
    }

    /// `true` if a state moved from `before` to `end` over the last sub-interval (ending at
    /// `t`, state `y`) but does not move a little further along the velocity: it stopped
    /// inside that sub-interval (a slider's turn the sub-points stepped over).
    fn stops_after(&self, t: f64, y: &[f64], before: &States, end: &States) -> bool {
        let model = self.rhs.model();
        let n = model.n_dofs();
        let (q, v) = y.split_at(n);
        let theta = self.rhs.theta(t);
        let eps = 1e-9 * t.abs().max(1.0);
        let ahead: Vec<f64> = q.iter().zip(v).map(|(x, w)| x + eps * w).collect();
        model.elements().iter().enumerate().any(|(i, e)| {
            let Some(m) = e.law().memory() else {
                return false;
            };
            let len = m.state_len();
            if before[i][..len] == end[i][..len] {
                return false;
            }
            let mut p = end[i];
            m.step(theta, e.gather(&ahead), e.gather(v), &mut p[..len]);
            p[..len] == end[i][..len]
        })
    }

    /// Records the sample times up to `t` (`y_at` gives the state there).
    fn record(&mut self, t: f64, mut y_at: impl FnMut(f64) -> Option<Vec<f64>>) {
        let tiny = 1e-12 * t.abs().max(1.0);
        while self.next < self.times.len() && self.times[self.next] <= t + tiny {
            self.out[self.next] = y_at(self.times[self.next]);
            self.next += 1;
        }
    }
}

impl Solout<f64, Vec<f64>> for Commit<'_, '_> {
    fn solout<I>(
        &mut self,
        t_curr: f64,
        t_prev: f64,
        y_curr: &Vec<f64>,
        _y_prev: &Vec<f64>,
        interp: &mut I,
        solution: &mut Solution<f64, Vec<f64>>,
    ) -> ControlFlag<f64, Vec<f64>>
    where
        I: Interpolation<f64, Vec<f64>> + ?Sized,
    {
        if t_curr <= t_prev {
            // The start (or a restart): nothing to commit.
            self.record(t_curr, |_| Some(y_curr.clone()));
            return ControlFlag::Continue;
        }
        let mut at = |t: f64| -> Option<Vec<f64>> {
            if t >= t_curr {
                Some(y_curr.clone())
            } else {
                interp.interpolate(t).ok()
            }
        };
        let (mut a, mut b) = (t_prev, t_curr);
        let mut path: States = self.rhs.states.borrow().clone();
        let mut cut = None;
        for _ in 0..LEVELS {
            // The path at a, τ_1, ..., up to the first sub-point where the frozen force differs.
            let mut hist = vec![path.clone()];
            let mut differs = None;
            for k in 1..=SUBSTEPS {
                let t = if k == SUBSTEPS {
                    b
                } else {
                    a + (b - a) * k as f64 / SUBSTEPS as f64
                };
                let Some(y) = at(t) else {
                    *self.error = Some(format!("no dense output at t = {t}"));
                    return ControlFlag::Terminate;
                };
                let mut p = hist[k - 1].clone();
                if !self.advance(t, &y, &mut p) {
                    differs = Some(k);
                    break;
                }
                hist.push(p);
            }
            let tau = |k: usize| a + (b - a) * k as f64 / SUBSTEPS as f64;
            match differs {
                // The state stopped (a slider's turn) between τ_{k-2} and τ_k, where the path
                // may have stepped over the extremum: refine both sub-intervals.
                Some(k) => {
                    cut = Some((tau(k - 1), hist[k - 1].clone()));
                    let k0 = k.saturating_sub(2);
                    (a, b) = (tau(k0), tau(k));
                    path = hist[k0].clone();
                }
                None => {
                    let last = hist.len() - 1;
                    // Still moving at the end but stopping right after it: the extremum lies in
                    // the last sub-interval; refine it (the next step can no longer).
                    let y = at(b).unwrap_or_else(|| y_curr.clone());
                    if self.stops_after(b, &y, &hist[last - 1], &hist[last]) {
                        cut = None;
                        (a, path) = (tau(last - 1), hist[last - 1].clone());
                        continue;
                    }
                    path = hist.pop().unwrap_or(path);
                    if cut.is_some() {
                        cut = Some((b, path.clone()));
                    }
                    break;
                }
            }
        }
        let restart = match cut {
            Some((tc, p)) if tc < t_curr => Some(if tc > t_prev {
                (tc, p)
            } else {
                // The state stopped right at the step's start: restart just after it.
                let mut p = p;
                if let Some(y) = at(b) {
                    self.advance(b, &y, &mut p);
                }
                (b, p)
            }),
            Some((_, p)) => {
                path = p;
                None
            }
            None => None,
        };
        match restart {
            // The frozen state held over the whole step.
            None => {
                *self.rhs.states.borrow_mut() = path;
                self.record(t_curr, &mut at);
                if t_curr >= self.t_end - 1e-12 * self.t_end.abs().max(1.0) {
                    solution.push(t_curr, y_curr.clone());
                }
                ControlFlag::Continue
            }
            // Restart where it stopped holding.
            Some((tc, p)) => {
                let Some(yc) = at(tc) else {
                    *self.error = Some(format!("no dense output at t = {tc}"));
                    return ControlFlag::Terminate;
                };
                *self.rhs.states.borrow_mut() = p;
                self.record(tc, &mut at);
                *self.restart = Some((tc, yc));
                ControlFlag::Terminate
            }
        }
    }
}

/// Most restarts of the integrator within one segment: a law's state that holds and lets go
/// again and again (chattering) would restart it without end. A smooth orbit restarts a few
/// times per switch of a law.
const MAX_RESTARTS: usize = 10_000;

/// Integrates the segment `[w0, w1]` (angles) of period `p` (start time `t_period`) from `y`,
/// committing the states of the laws with memory; samples `q` at the angles `2π j / N` inside
/// the segment if `samples` is given. Returns the end time and state.
#[allow(clippy::too_many_arguments)]
pub(super) fn integrate_segment(
    rhs: &Rhs,
    (rtol, atol, h_max): (f64, &[f64], Option<f64>),
    (ta, tb): (f64, f64),
    (w0, w1, t_period, omega): (f64, f64, f64, f64),
    y: Vec<f64>,
    samples: Option<&mut Vec<Vec<f64>>>,
    steps: &mut usize,
    evals: &mut usize,
) -> Result<(f64, Vec<f64>)> {
    let ns = samples.as_ref().map_or(0, |s| s[0].len());
    let js: Vec<usize> = (0..ns)
        .filter(|&j| {
            let th = TAU * j as f64 / ns as f64;
            th >= w0 && th < w1
        })
        .collect();
    let times: Vec<f64> = js
        .iter()
        .map(|&j| t_period + TAU * j as f64 / ns as f64 / omega)
        .collect();
    let mut out = vec![None; times.len()];
    let mut error = None;
    let (mut t, mut y, mut next) = (ta, y, 0);
    // A fresh integrator from every restart (its first step chosen for what is left).
    for restarts in 0.. {
        if restarts >= MAX_RESTARTS {
            return Err(Error::TimeIntegration {
                reason: format!(
                    "a law with memory switched between holding and moving {MAX_RESTARTS} times within one segment at t = {t:.6e} s (it chatters: a contact or slider on an almost free or very stiff DOF); check the stiffness, masses and loads for a unit mistake (in a stability computation, --no-stability skips it)"
                ),
            });
        }
        let mut restart = None;
        let commit = Commit {
            rhs,
            t_end: tb,
            times: &times,
            out: &mut out,
            next,
            error: &mut error,
            restart: &mut restart,
        };
        let mut method = ExplicitRungeKutta::dop853()
            .rtol(rtol)
            .atol(atol.to_vec())
            .max_steps(usize::MAX / 4);
        if let Some(h) = h_max {
            method = method.h_max(h);
        }
        let sol = IVP::ode(rhs, t, tb, y.clone())
            .method(method)
            .solout(commit)
            .solve()
            .map_err(|e| Error::TimeIntegration {
                reason: format!("{e:?}"),
            })?;
        if let Some(reason) = error {
            return Err(Error::TimeIntegration { reason });
        }
        *steps += sol.steps.accepted + sol.steps.rejected;
        *evals += sol.evals.function;
        next = out.iter().take_while(|o| o.is_some()).count();
        match restart {
            Some((tc, yc)) => (t, y) = (tc, yc),
            None => {
                let (t_end, y_end) = sol.last().map_err(|e| Error::TimeIntegration {
                    reason: e.to_string(),
                })?;
                (t, y) = (*t_end, y_end.clone());
                break;
            }
        }
    }
    if let Some(rows) = samples {
        for (&j, yj) in js.iter().zip(&out) {
            let Some(yj) = yj else {
                return Err(Error::TimeIntegration {
                    reason: format!("sample {j} of the period was not reached"),
                });
            };
            for (i, row) in rows.iter_mut().enumerate() {
                row[j] = yj[i];
            }
        }
    }
    Ok((t, y))
}
