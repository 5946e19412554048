//! The pseudo-arclength predictor–corrector (see the module documentation of
//! [`continuation`](super)): the first point, then [`Continuation::follow`] along the branch.

use super::bordered::{tangent, Scales, Target, Tracer};
use super::pipeline::{Sink, Traced, LOOKAHEAD};
use super::point::NewPoint;
use super::{Branch, BranchStop, Continuation};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solve::robust_start;
use crate::HarmonicBasis;
use num_complex::Complex64;
use std::sync::mpsc::sync_channel;

/// A step that turned the tangent by less than this (rad) grows even where the corrector
/// needed up to five iterations.
const FLAT_ANGLE: f64 = 0.1;

/// The angle (rad) between two unit tangents.
fn turned(a: &[f64], b: &[f64]) -> f64 {
    let cos: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    cos.clamp(-1.0, 1.0).acos()
}

/// Where a branch is followed: it lands exactly on `to` and stops there; with `back`, also on
/// `back` should it leave the range that way (a secondary branch may head either way, and
/// turn). A branch from a solve has no `back`: past a fold it may leave the range through its
/// start and come back (the Duffing S-curve started inside its hysteresis).
///
/// With `rejoin` (a mask of the unknowns that vanish on the parent branch of a switched branch:
/// the odd harmonics below a period doubling, the even ones of a half-wave symmetric orbit), the
/// branch also stops once it has left that subspace and comes back into it, or passes through
/// it (its part in the mask reverses between two points): it has reached its parent again, at
/// its other branch point, and what follows is the parent or the mirror image of what is known.
#[derive(Debug, Clone, Copy)]
pub(super) struct Range<'a> {
    pub(super) back: Option<f64>,
    pub(super) to: f64,
    pub(super) rejoin: Option<&'a [bool]>,
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
        if let Some(branch) = self.run_time_invariant(model, basis, to, &mut progress)? {
            return Ok(branch);
        }
        let from = basis.omega();
        let mut hb = HarmonicBalance::with_formulation(model, basis, self.formulation)?;
        crate::solve::check_dense_for_continuation(&hb)?;
        if let Some(q) = initial {
            if hb.unknowns_of(q).is_none() {
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
        let mut start = robust_start(&mut hb, &self.method, initial, self.tolerance, &mut ws)?;
        if !start.solution.is_converged() && self.stability.is_some() {
            // Last resort (the inner continuation runs without stability, so no recursion).
            start = super::solve_robustly(model, basis, self)?;
        }
        let mut branch = Branch::new(model, basis, start.how.clone());
        let start = start.solution;
        if !start.is_converged() {
            branch.stop = BranchStop::StartFailed {
                reason: branch.start.clone(),
            };
            return Ok(branch);
        }
        let layout = hb.layout();
        let m = layout.len();
        let mut x = vec![0.0; m];
        // The solution carries all DOFs; the unknowns may be the element coordinates.
        let unknowns = hb
            .unknowns_of_full(start.harmonics())
            .ok_or_else(|| Error::Solver {
                reason: "continuation start: the solution does not match the discretisation".into(),
            })?;
        layout.pack(&unknowns, &mut x);
        let mut tr = Tracer::new(hb, Scales::new(0.0, from, 1.0));
        tr.sc = Scales::new(tr.rms(&x), from, tr.load_norm());
        let direction = if to >= from { 1.0 } else { -1.0 };
        // Initial tangent from R_x dx = -R_Ω: t ∝ (dx/dΩ · s_Ω/s_x, 1).
        let mut t = vec![0.0; m + 1];
        t[m] = 1.0;
        if tr.factor(&x, from, &t)?.is_none() {
            branch.stop = BranchStop::Singular { omega: from };
            return Ok(branch);
        }
        tangent(&mut tr.b, &mut t);
        if t[m] * direction < 0.0 {
            t.iter_mut().for_each(|v| *v = -*v);
        }
        if let Some(reason) = self.push(&mut branch, model, &tr.hb, &x, from, start.residual()) {
            branch.stop = BranchStop::StabilityFailed {
                omega: from,
                reason,
            };
            return Ok(branch);
        }
        let range = Range {
            back: None,
            to,
            rejoin: None,
        };
        self.follow(&mut tr, model, &mut branch, x, from, t, range, progress);
        self.locate_bifurcations(model, basis, &mut branch)?;
        Ok(branch)
    }

    /// Continues `branch` (its last point `(x, Ω)` with unit tangent `t` in the scaled
    /// unknowns) until it reaches `range.to`, leaves the range through `range.back`, or stops.
    /// With the stability on, a second core and a last point whose stability took at least
    /// [`Continuation::stability_worker`], the points' stability is computed by a worker while
    /// the next points are traced ([`pipeline`](super::pipeline)): the same branch.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn follow(
        &self,
        tr: &mut Tracer,
        model: &Model,
        branch: &mut Branch,
        x: Vec<f64>,
        omega: f64,
        t: Vec<f64>,
        range: Range,
        mut progress: impl FnMut(f64),
    ) {
        let from = omega;
        let stop = if self.pipelined(model, branch) {
            let (tx, rx) = sync_channel(LOOKAHEAD);
            let len = branch.points.len();
            let (x0, t0) = (x.clone(), t.clone());
            let outcome = std::thread::scope(|s| {
                let worker = std::thread::Builder::new()
                    .spawn_scoped(s, || self.append_all(branch, model, rx))
                    .ok()?;
                let mut sink = Sink::Worker { tx, len };
                let stop = self.trace(tr, model, &mut sink, x, omega, t, range, &mut progress);
                drop(sink);
                let failure = worker
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e));
                Some((stop, failure))
            });
            match outcome {
                // A failed stability ends the branch there, whatever the tracer did after it.
                Some((_, Some((omega, reason)))) => {
                    Some(BranchStop::StabilityFailed { omega, reason })
                }
                Some((stop, None)) => stop,
                // No thread to be had: on this one.
                None => {
                    let mut sink = Sink::Direct(branch);
                    self.trace(tr, model, &mut sink, x0, omega, t0, range, &mut progress)
                }
            }
        } else {
            let mut sink = Sink::Direct(branch);
            self.trace(tr, model, &mut sink, x, omega, t, range, progress)
        };
        if let Some(stop) = stop {
            branch.stop = stop;
        }
        super::point::classify_turns(branch);
        if branch.points.len() >= self.max_points && branch.stop == BranchStop::Reached {
            let last = branch.points.last().map_or(from, |p| p.omega);
            if (last - range.to) * if range.to >= from { 1.0 } else { -1.0 } < 0.0 {
                branch.stop = BranchStop::MaxPoints;
            }
        }
    }

    /// The predictor–corrector loop of [`Continuation::follow`], its points into `sink`: why
    /// it stopped, `None` at the largest number of points.
    #[allow(clippy::too_many_arguments)]
    fn trace(
        &self,
        tr: &mut Tracer,
        model: &Model,
        sink: &mut Sink,
        mut x: Vec<f64>,
        mut omega: f64,
        mut t: Vec<f64>,
        range: Range,
        mut progress: impl FnMut(f64),
    ) -> Option<BranchStop> {
        let m = x.len();
        let (from, to) = (omega, range.to);
        let direction = if to >= from { 1.0 } else { -1.0 };
        let mut step = self.initial_step;
        let mut left_parent = false;
        let (mut xp, mut x_new) = (vec![0.0; m], vec![0.0; m]);
        let mut land_row = vec![0.0; m + 1];
        land_row[m] = 1.0;
        while sink.len() < self.max_points {
            let op = tr.sc.predict(&x, omega, &t, step, &mut xp);
            x_new.copy_from_slice(&xp);
            let mut o_new = op;
            let target = Target {
                xp: &xp,
                op,
                row: &t,
                chord: true,
            };
            let Some((iterations, mut rel)) = self.correct(tr, &mut x_new, &mut o_new, &target)
            else {
                step *= 0.5;
                if step < self.min_step {
                    return Some(BranchStop::StepTooSmall { omega });
                }
                continue;
            };
            // Tangent at the new point (the bordered matrix factored there with the old t, or
            // after chord steps at the iterate where Ω was kept: a predictor either way).
            let t_prev = t.clone();
            tangent(&mut tr.b, &mut t);
            let turn = t_prev[m] * t[m] < 0.0;
            let turn_omega = turn.then(|| {
                let h = tr.distance(&x_new, o_new, &x, omega);
                let ends = [(0.0, t_prev[m]), (h, t[m])];
                // Fallback: dΩ/ds linear in s between both tangents.
                self.locate_turn(tr, &x, omega, &t_prev, ends)
                    .unwrap_or_else(|| {
                        let s_star = h * t_prev[m] / (t_prev[m] - t[m]);
                        omega + tr.sc.so * t_prev[m] * s_star / 2.0
                    })
            });
            let end = if (o_new - to) * direction >= 0.0 {
                Some(to)
            } else {
                range.back.filter(|b| (o_new - b) * direction <= 0.0)
            };
            let mut landed = false;
            if let (Some(to), false) = (end, turn) {
                // Land exactly on the end: correct the interpolated point with Ω fixed.
                let a = (to - omega) / (o_new - omega);
                let xl: Vec<f64> = (0..m).map(|i| x[i] + a * (x_new[i] - x[i])).collect();
                let mut xc = xl.clone();
                let mut oc = to;
                let land = Target {
                    xp: &xl,
                    op: to,
                    row: &land_row,
                    chord: false,
                };
                if let Some((_, r)) = self.correct(tr, &mut xc, &mut oc, &land) {
                    x_new.copy_from_slice(&xc);
                    o_new = to;
                    rel = r;
                    landed = true;
                }
            }
            // Back on the parent: landed in its subspace, or passed through it (the part outside
            // reverses, as on the mirror image or the orbit shifted by T).
            let rejoined = range.rejoin.is_some_and(|mask| {
                let (mut inside, mut all, mut along) = (0.0, 0.0, 0.0);
                for i in 0..m {
                    all += x_new[i] * x_new[i];
                    if mask[i] {
                        inside += x_new[i] * x_new[i];
                        along += x_new[i] * x[i];
                    }
                }
                let share = (inside / all.max(f64::MIN_POSITIVE)).sqrt();
                let back = left_parent && (share < 1e-9 || along < 0.0);
                left_parent |= share > 1e-6;
                back
            });
            // Past a table over speed (its loads held at its ends there) the branch stops: its
            // points would follow loads nobody gave.
            if let Err(e) = model.check_load_speeds(o_new, o_new) {
                let reason = e.to_string();
                return Some(BranchStop::Failed {
                    parameter: o_new,
                    reason,
                });
            }
            // Rescale x to the new point's size, keeping the tangent's direction.
            let sx_new = tr.rms(&x_new);
            for v in t[..m].iter_mut() {
                *v *= tr.sc.sx / sx_new;
            }
            let norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
            t.iter_mut().for_each(|v| *v /= norm);
            tr.sc.sx = sx_new;
            x.copy_from_slice(&x_new);
            omega = o_new;
            // Locating a turn moves `hb` to other Ω: the recovery of all DOFs needs the point's.
            if tr.hb.basis().omega() != omega {
                if let Err(e) = tr.hb.set_omega(omega) {
                    let reason = e.to_string();
                    return Some(BranchStop::StabilityFailed { omega, reason });
                }
            }
            // Loads that follow the speed: residuals relative to this point's load.
            if model.has_speed_dependent_loads() {
                let ext = tr.load_norm();
                rel *= tr.sc.ext / ext;
                tr.sc.ext = ext;
            }
            let failed = match new_point(model, &tr.hb, &x, omega, rel) {
                Ok(point) => {
                    let traced = Traced {
                        point,
                        turn,
                        turn_omega,
                    };
                    sink.append(self, model, traced)
                }
                Err(reason) => Some(reason),
            };
            if let Some(reason) = failed {
                return Some(BranchStop::StabilityFailed { omega, reason });
            }
            progress(((omega - from) / (to - from)).clamp(0.0, 1.0));
            if landed || (omega - to) * direction >= 0.0 {
                return Some(BranchStop::Reached);
            }
            if self.cancel.is_cancelled() {
                return Some(BranchStop::Cancelled { parameter: omega });
            }
            if rejoined {
                return Some(BranchStop::Rejoined { omega });
            }
            // A stiff contact opening or closing costs corrector iterations, not curvature:
            // where the tangent hardly turned, the step grows even after up to five.
            let flat = iterations <= 5 && turned(&t_prev, &t) < FLAT_ANGLE;
            if iterations <= 2 || flat {
                step = (step * 1.5).min(self.max_step);
            } else if iterations >= 5 {
                step *= 0.7;
            }
        }
        None
    }

    /// Appends the point `x` at `omega` (on the basis of `hb`); `Some(reason)` if its
    /// stability failed.
    pub(super) fn push(
        &self,
        branch: &mut Branch,
        model: &Model,
        hb: &HarmonicBalance,
        x: &[f64],
        omega: f64,
        residual: f64,
    ) -> Option<String> {
        match new_point(model, hb, x, omega, residual) {
            Ok(point) => self.push_point(branch, model, point),
            Err(reason) => Some(reason),
        }
    }
}

/// The point `x` at `omega` (on the basis of `hb`) with all DOFs' harmonics (the condensed
/// formulation recovers them from the coordinates; `hb` sits at `omega` after the corrector).
fn new_point(
    model: &Model,
    hb: &HarmonicBalance,
    x: &[f64],
    omega: f64,
    residual: f64,
) -> std::result::Result<NewPoint, String> {
    let mut unknowns = vec![Complex64::default(); hb.len()];
    hb.layout().unpack(x, &mut unknowns);
    let harmonics = if hb.is_condensed() {
        hb.full_harmonics(&unknowns, &mut hb.workspace().eval)
            .map_err(|e| e.to_string())?
    } else {
        unknowns
    };
    let basis = hb.basis().with_omega(omega).map_err(|e| e.to_string())?;
    NewPoint::new(model, basis, harmonics, omega, residual)
}
