//! Where [`Continuation::follow`] puts its points: appended on the tracing thread, or, with
//! the Floquet stability on, a second core and a stability that takes long enough
//! ([`Continuation::stability_worker`]), by a worker thread that computes each point's
//! stability while the tracing thread already corrects the next points.
//!
//! The branch does not depend on the stability of its points, except that a failed stability
//! ends it there. The worker appends the points in order, with the same [`FloquetCache`] carried
//! from point to point, so its branch is the serial one: the points the tracer computed after
//! a failed point are dropped, and the branch stops at the failure as it would have serially.
//! The tracer runs at most [`LOOKAHEAD`] points ahead.
//!
//! [`FloquetCache`]: crate::stability::FloquetCache

use super::point::NewPoint;
use super::{Branch, Continuation};
use crate::model::Model;
use std::sync::mpsc::{Receiver, SyncSender};

/// Points the tracer may compute ahead of the worker.
pub(super) const LOOKAHEAD: usize = 4;

/// A traced point on its way to the branch, with what the tracer knows of a turn before it.
pub(super) struct Traced {
    pub(super) point: NewPoint,
    pub(super) turn: bool,
    pub(super) turn_omega: Option<f64>,
}

/// The tracer's end of the branch.
pub(super) enum Sink<'b> {
    /// Appends on the tracing thread.
    Direct(&'b mut Branch),
    /// Sends to the worker ([`Continuation::append_all`]), which hangs up at a failed point.
    Worker {
        tx: SyncSender<Traced>,
        /// Points on the branch before the first one sent, plus those sent.
        len: usize,
    },
}

impl Sink<'_> {
    /// Points on the branch, counting those on their way.
    pub(super) fn len(&self) -> usize {
        match self {
            Sink::Direct(branch) => branch.points.len(),
            Sink::Worker { len, .. } => *len,
        }
    }

    /// Appends `traced`; `Some(reason)` if the branch must end here (its stability failed; with
    /// a worker also at a later point, once the worker reports an earlier failure).
    pub(super) fn append(
        &mut self,
        continuation: &Continuation,
        model: &Model,
        traced: Traced,
    ) -> Option<String> {
        match self {
            Sink::Direct(branch) => continuation.append(branch, model, traced),
            Sink::Worker { tx, len } => {
                // The max |q| of every DOF here, the stability on the worker; with the HB
                // orbit's stability (a third of the exact orbit's work) the worker has time
                // for both, and the tracer is the slower thread.
                let mut traced = traced;
                let harmonic = continuation
                    .stability
                    .is_some_and(|s| s.orbit == crate::stability::Orbit::Harmonic);
                if !harmonic {
                    traced.point.max_abs = Some(traced.point.solution.max_abs_all());
                }
                if tx.send(traced).is_err() {
                    return Some("stability failed at an earlier point".to_string());
                }
                *len += 1;
                None
            }
        }
    }
}

impl Continuation {
    /// Appends a traced point to `branch` with its stability and turn flags; `Some(reason)` if
    /// its stability failed.
    pub(super) fn append(
        &self,
        branch: &mut Branch,
        model: &Model,
        traced: Traced,
    ) -> Option<String> {
        let failed = self.push_point(branch, model, traced.point);
        if let Some(last) = branch.points.last_mut() {
            last.fold = traced.turn;
            last.fold_omega = traced.turn_omega;
        }
        failed
    }

    /// The worker: appends every point received, in order, until the first whose stability
    /// failed (`(Ω, reason)` returned; dropping `rx` then tells the tracer).
    pub(super) fn append_all(
        &self,
        branch: &mut Branch,
        model: &Model,
        rx: Receiver<Traced>,
    ) -> Option<(f64, String)> {
        for traced in rx {
            let omega = traced.point.solution.basis().omega();
            if let Some(reason) = self.append(branch, model, traced) {
                return Some((omega, reason));
            }
        }
        None
    }

    /// Whether `branch` of `model` is followed with a worker: stability on, its last point's
    /// stability took at least
    /// [`Continuation::stability_worker`], and a second core (`HBAL_THREADS` not 1).
    pub(super) fn pipelined(&self, _model: &Model, branch: &Branch) -> bool {
        let took = branch.stability_cache.last_time();
        self.stability.is_some()
            && self
                .stability_worker
                .is_some_and(|from| took.is_some_and(|t| t >= from))
            && crate::linear::parallel::second_thread()
    }
}
