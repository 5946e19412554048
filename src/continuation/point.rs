//! A new point on a branch: its stability, whether a turning point before it is a real fold,
//! and which bifurcation a stability change is.
//!
//! A turning point of the discretised branch (the tangent's Ω component changes sign) is a
//! fold of the exact problem when the number of real multipliers greater than 1 changes parity
//! between its two neighbours (`det(I - Φ)` changes sign: a multiplier passes through +1).
//! Non-smooth branches also turn at corners, and an under-sampled contact kink makes the
//! discretised branch zig-zag; the exact orbits on both sides then have the same multipliers,
//! and the turn is reported as spurious, not as a fold.
//!
//! Turns and parity changes close together (within 12 points and 5e-3 relative in Ω) form one
//! cluster: near a fold of a non-smooth branch the discretised branch may zig-zag and the
//! exact orbits' multipliers flicker around 1. A cluster with turns is one fold (at its first
//! turn) if the parity of the real multipliers above 1 differs between the point two before
//! the cluster and the point after it (without stability: if it has an odd number of turns);
//! otherwise all its turns are spurious.

use super::{Branch, BranchPoint, Continuation};
use crate::model::Model;
use crate::solution::Solution;
use crate::stability::{Bifurcation, FloquetOptions};
use crate::HarmonicBasis;
use num_complex::Complex64;

/// Why a turning point of the discretised branch is a fold or not: a multiplier crosses +1
/// between two orbits exactly where the number of real multipliers above +1 changes parity.
/// Turns and parity changes close together form one cluster (a zig-zag near a fold of a
/// non-smooth branch); the cluster is compared from the point two before it to the point
/// after it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TurnEvidence {
    /// Ω of the point before the cluster, and its real multipliers above +1 (`None` if its
    /// stability is unknown).
    pub before: (f64, Option<usize>),
    /// The same after the cluster.
    pub after: (f64, Option<usize>),
    /// Turns in the cluster (only its first can be the fold).
    pub turns: usize,
}

impl TurnEvidence {
    /// The reason in words, with `speed` formatting an Ω.
    pub fn describe(&self, speed: &dyn Fn(f64) -> String) -> String {
        let side = |(w, c): (f64, Option<usize>)| match c {
            Some(c) => format!("{c} at {}", speed(w)),
            None => format!("unknown at {}", speed(w)),
        };
        let counts = format!(
            "real multipliers above +1: {} and {}",
            side(self.before),
            side(self.after)
        );
        let cluster = if self.turns > 1 {
            format!(", {} turns close together", self.turns)
        } else {
            String::new()
        };
        match (self.before.1, self.after.1) {
            (Some(a), Some(b)) if a % 2 == b % 2 => {
                format!("{counts} (no multiplier crossed +1){cluster}")
            }
            (Some(_), Some(_)) => {
                format!("{counts} (a multiplier crossed +1: the fold is the first turn){cluster}")
            }
            _ => format!("{counts} (decided by the number of turns){cluster}"),
        }
    }
}

/// What the caller knows about a new point.
pub(super) struct NewPoint {
    /// The periodic solution (all DOFs) at the point's Ω.
    pub solution: Solution,
    pub parameter: f64,
    /// `max |q_i|` of every DOF if already known (computed by the tracer of a pipelined
    /// sweep, which would otherwise wait for the worker).
    pub max_abs: Option<Vec<f64>>,
    /// The error estimate and the multipliers if already known (the exact piecewise
    /// solution has both).
    pub estimate: Option<crate::solve::ErrorEstimate>,
    pub floquet: Option<crate::stability::Floquet>,
}

impl NewPoint {
    /// The point of `parameter` with the harmonics `harmonics` (all DOFs of `model`) on
    /// `basis`, its relative residual `residual`.
    pub(super) fn new(
        model: &Model,
        basis: HarmonicBasis,
        harmonics: Vec<Complex64>,
        parameter: f64,
        residual: f64,
    ) -> Result<Self, String> {
        let solution =
            Solution::from_harmonics(basis, model.dof_names().to_vec(), harmonics, residual)
                .map_err(|e| e.to_string())?;
        Ok(Self {
            solution,
            parameter,
            max_abs: None,
            estimate: None,
            floquet: None,
        })
    }
}

impl Continuation {
    /// Appends `p` to `branch` with its stability. A failed stability computation still
    /// appends the point (without multipliers) and returns the reason.
    pub(super) fn push_point(
        &self,
        branch: &mut Branch,
        model: &Model,
        p: NewPoint,
    ) -> Option<String> {
        let sol = p.solution;
        let omega = sol.basis().omega();
        let prev = branch.points.last().and_then(|q| q.floquet.clone());
        let prev_stable = branch.points.last().and_then(|q| q.stable());
        let (floquet, failure) = match &self.stability {
            Some(_) if p.floquet.is_some() => (p.floquet, None),
            // Laws with memory in a large or free-free model: stability unknown, the branch
            // goes on.
            Some(_) if crate::stability::unavailable(model).is_some() => (None, None),
            Some(options) => {
                // The modes and the last orbit correction carry over from point to point; the
                // reduction's estimate is computed where a label is decided: at the first
                // point and wherever the stability changes.
                let started = std::time::Instant::now();
                let cache = &mut branch.stability_cache;
                let quick = FloquetOptions {
                    estimate: false,
                    ..*options
                };
                let f = quick.compute_with(model, &sol, cache).and_then(|mut f| {
                    if options.estimate && prev_stable != Some(f.is_stable()) {
                        options.add_estimate(model, &sol, &mut f, cache)?;
                    }
                    Ok(f)
                });
                cache.set_last_time(started.elapsed());
                match f {
                    // A non-finite multiplier would reach the outputs as NaN or `null`: it
                    // ends the branch here, named, instead.
                    Ok(f)
                        if !f
                            .multipliers
                            .iter()
                            .all(|m| m.re.is_finite() && m.im.is_finite()) =>
                    {
                        (
                            None,
                            Some(format!(
                                "stability at Ω = {omega}: non-finite Floquet multiplier"
                            )),
                        )
                    }
                    Ok(f) => (Some(f), None),
                    Err(e) => (None, Some(format!("stability at Ω = {omega}: {e}"))),
                }
            }
            None => (None, None),
        };
        let stable = floquet.as_ref().map(|f| f.is_stable());
        // The kind comes from the unstable side, where the critical multiplier is outside.
        let bifurcation = match (prev_stable, stable) {
            (Some(true), Some(false)) => floquet.as_ref().and_then(|f| f.critical()),
            (Some(false), Some(true)) => prev.as_ref().and_then(|f| f.critical()),
            _ => None,
        };
        let max_abs = p.max_abs.unwrap_or_else(|| sol.max_abs_all());
        let truncation = sol.truncation_estimate();
        let estimate = p.estimate.or_else(|| {
            self.error_estimate
                .then(|| crate::solve::estimate_error(model, &sol).ok())
                .flatten()
        });
        let finite = |e: f64| Some(e).filter(|e| e.is_finite());
        let error_estimate = estimate.and_then(|e| finite(e.relative));
        let error_estimate_harmonics = estimate.and_then(|e| finite(e.kept_harmonics));
        let worst_quantity = estimate.and_then(|e| e.worst_quantity);
        let quadrature = estimate.and_then(|e| e.quadrature).map(|q| q.relative);
        let residual = sol.residual();
        branch.points.push(BranchPoint {
            parameter: p.parameter,
            harmonics: sol.harmonics,
            omega,
            max_abs,
            residual,
            truncation,
            error_estimate,
            error_estimate_harmonics,
            worst_quantity,
            quadrature,
            floquet,
            // Set by the caller for a turn, then [`classify_turns`] decides once the
            // neighbours are known.
            fold: false,
            spurious_turn: false,
            turn_evidence: None,
            fold_omega: None,
            bifurcation,
            bifurcation_omega: None,
        });
        failure
    }
}

/// Decides which tentative turns of `branch` are folds (module documentation).
pub(super) fn classify_turns(branch: &mut Branch) {
    let pts = &mut branch.points;
    let unstable = |p: &BranchPoint| p.floquet.as_ref().map(|f| f.real_unstable());
    let parity = |p: &BranchPoint| unstable(p).map(|c| c % 2);
    // Events: tentative turns, and points whose parity differs from the previous point's.
    let mut events: Vec<(usize, bool)> = Vec::new();
    for i in 0..pts.len() {
        let changed =
            i > 0 && matches!((parity(&pts[i - 1]), parity(&pts[i])), (Some(a), Some(b)) if a != b);
        if pts[i].fold || changed {
            events.push((i, pts[i].fold));
        }
    }
    let mut clusters: Vec<Vec<(usize, bool)>> = Vec::new();
    for e in events {
        match clusters.last_mut() {
            Some(c)
                if e.0 - c[c.len() - 1].0 <= CLUSTER_POINTS
                    && (pts[e.0].omega - pts[c[c.len() - 1].0].omega).abs()
                        <= CLUSTER_WIDTH * pts[e.0].omega.abs() =>
            {
                c.push(e)
            }
            _ => clusters.push(vec![e]),
        }
    }
    for c in clusters {
        let turns: Vec<usize> = c.iter().filter(|e| e.1).map(|e| e.0).collect();
        if turns.is_empty() {
            // A multiplier through +1 without a turn: a branch point.
            for &(i, _) in &c {
                if pts[i].bifurcation == Some(Bifurcation::Fold) {
                    pts[i].bifurcation = Some(Bifurcation::BranchPoint);
                }
            }
            continue;
        }
        let before = c[0].0.saturating_sub(2);
        let after = (c[c.len() - 1].0 + 1).min(pts.len() - 1);
        let confirmed = match (parity(&pts[before]), parity(&pts[after])) {
            (Some(a), Some(b)) => a != b,
            _ => turns.len() % 2 == 1,
        };
        let evidence = TurnEvidence {
            before: (pts[before].omega, unstable(&pts[before])),
            after: (pts[after].omega, unstable(&pts[after])),
            turns: turns.len(),
        };
        for (j, &i) in turns.iter().enumerate() {
            let fold = confirmed && j == 0;
            pts[i].fold = fold;
            pts[i].spurious_turn = !fold;
            pts[i].turn_evidence = Some(evidence);
            if !fold {
                pts[i].fold_omega = None;
            }
        }
    }
}

/// Events at most this many points apart belong to one cluster...
const CLUSTER_POINTS: usize = 12;
/// ...if their Ω also differ by at most this fraction.
const CLUSTER_WIDTH: f64 = 5e-3;
