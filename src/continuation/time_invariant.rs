//! The frequency response of a linear time-invariant model without continuation.
//!
//! Where every element is linear and time-invariant, the branch is the graph of
//! `Q_k(Ω) = Z_k(Ω)⁻¹ F_k` over Ω: no turning points, one solve per harmonic per point
//! ([`solve_time_invariant`]), the multipliers from the state matrix's eigenvalues (computed
//! once for the whole sweep, [`crate::stability`]) and an error estimate by iterative
//! refinement. The points are placed along the curve in the scaled unknowns
//! `y = (x/s_x, Ω/s_Ω)` as by the continuation: each chord at most [`Continuation::max_step`]
//! long, the tangent `(dx/dΩ s_Ω/s_x, 1)` (from `dQ_k/dΩ = -Z_k⁻¹ (dZ_k/dΩ) Q_k`) turning by
//! at most [`MAX_TURN`] from one point to the next (a resonance peak gets its points), `s_x` the norm of the last point (a step changes the response by at most
//! `max_step` of itself, whatever the number of unknowns; a resonance peak `A` times the response before it
//! costs points in proportion to `ln A`, as on the log scale of its plot, and a small peak
//! after a large one is resolved as well)
//! and `s_Ω` the larger of the start speed and a hundredth of the range (a run-up from nearly
//! standing still still reaches `--to` in a few hundred points).

use super::point::NewPoint;
use super::{Branch, BranchStop, Continuation};
use crate::error::Result;
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::residual::Workspace;
use crate::solve::{omega_slope, solve_time_invariant, time_invariant_estimate};
use crate::{Formulation, HarmonicBasis};

/// Largest angle (rad) between the tangents at successive points; a step that turns more is taken again at
/// half the length.
pub const MAX_TURN: f64 = 0.2;

/// How the first point was found, for [`Branch::start`].
pub(super) const START: &str = "one solve per harmonic (linear time-invariant model)";

/// A solved point in the real layout with its scaled position.
struct Sample {
    omega: f64,
    x: Vec<f64>,
    /// `dx/dΩ`.
    slope: Vec<f64>,
    solution: crate::Solution,
}

impl Continuation {
    /// The branch of the linear time-invariant `model` from `basis.omega()` to `to` (module
    /// documentation); `None` where the shortcut does not apply (a time-varying or nonlinear
    /// element, a subharmonic basis, a model for the condensed formulation).
    pub(super) fn run_time_invariant(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        to: f64,
        progress: &mut impl FnMut(f64),
    ) -> Result<Option<Branch>> {
        if !model.is_linear_time_invariant()
            || basis.subharmonic() != 1
            || self.formulation.resolve(model) == Formulation::Condensed
        {
            return Ok(None);
        }
        let from = basis.omega();
        let mut hb = HarmonicBalance::with_formulation(model, basis, Formulation::Full)?;
        let mut ws = hb.workspace();
        let mut branch = Branch::new(model, basis, START.to_string());
        let Some(first) = sample(&mut hb, &mut ws, from)? else {
            return Ok(None);
        };
        let so = from.max((to - from).abs() / 100.0);
        let mut sx = Some(norm(&first.x)).filter(|v| *v > 0.0).unwrap_or(1.0);
        let chord = |a: &Sample, b: &Sample, sx: f64| -> f64 {
            let dx = a.x.iter().zip(&b.x).map(|(p, q)| ((q - p) / sx).powi(2));
            (dx.sum::<f64>() + ((b.omega - a.omega) / so).powi(2)).sqrt()
        };
        let tangent = |a: &Sample, sx: f64| -> Vec<f64> {
            let mut t: Vec<f64> = a.slope.iter().map(|d| d * so / sx).collect();
            t.push(1.0);
            t
        };
        let direction = if to >= from { 1.0 } else { -1.0 };
        let targets = resonances(model, from, to)?;
        let mut step = self.initial_step.min(self.max_step) * so;
        let mut last = first;
        if let Some(stop) = self.push_sample(&mut branch, model, &hb, &last) {
            branch.stop = stop;
            return Ok(Some(branch));
        }
        while (to - last.omega) * direction > 0.0 {
            if branch.points.len() >= self.max_points {
                branch.stop = BranchStop::MaxPoints;
                return Ok(Some(branch));
            }
            let next = loop {
                let mut omega = if (to - last.omega).abs() <= step * 1.000001 {
                    to
                } else {
                    last.omega + direction * step
                };
                // Never past a resonance without a point on it (a peak narrower than a step).
                if let Some(&t) = targets
                    .iter()
                    .find(|&&t| (t - last.omega) * direction > 0.0 && (omega - t) * direction > 0.0)
                {
                    omega = t;
                }
                let next = match sample(&mut hb, &mut ws, omega) {
                    Ok(Some(s)) => s,
                    Ok(None) | Err(_) if step > self.min_step * so => {
                        step *= 0.5;
                        continue;
                    }
                    Ok(None) => return Ok(None),
                    Err(e) => {
                        branch.stop = BranchStop::Failed {
                            parameter: omega,
                            reason: e.to_string(),
                        };
                        return Ok(Some(branch));
                    }
                };
                let length = chord(&last, &next, sx);
                let turn = angle(&tangent(&last, sx), &tangent(&next, sx));
                let refine = length > 1.5 * self.max_step || turn > MAX_TURN;
                if refine && step > self.min_step * so {
                    step *= 0.5;
                    continue;
                }
                let by_length = self.max_step / length.max(f64::MIN_POSITIVE);
                let by_turn = MAX_TURN / turn.max(1e-3);
                step *= by_length.min(by_turn).clamp(0.5, 2.0);
                break next;
            };
            last = next;
            sx = Some(norm(&last.x)).filter(|v| *v > 0.0).unwrap_or(sx);
            if let Some(stop) = self.push_sample(&mut branch, model, &hb, &last) {
                branch.stop = stop;
                return Ok(Some(branch));
            }
            progress(((last.omega - from) / (to - from)).clamp(0.0, 1.0));
            if self.cancel.is_cancelled() && (to - last.omega) * direction > 0.0 {
                branch.stop = BranchStop::Cancelled {
                    parameter: last.omega,
                };
                return Ok(Some(branch));
            }
        }
        Ok(Some(branch))
    }

    /// Appends `s` with its stability and error estimate (with the factors of `hb` at its Ω);
    /// the stop if its stability failed.
    fn push_sample(
        &self,
        branch: &mut Branch,
        model: &Model,
        hb: &HarmonicBalance,
        s: &Sample,
    ) -> Option<BranchStop> {
        let mut point = match point_of(model, &s.solution, s.omega) {
            Ok(p) => p,
            Err(reason) => {
                return Some(BranchStop::Failed {
                    parameter: s.omega,
                    reason,
                })
            }
        };
        if self.error_estimate {
            point.estimate = time_invariant_estimate(hb, &s.solution).ok();
        }
        self.push_point(branch, model, point)
            .map(|reason| BranchStop::StabilityFailed {
                omega: s.omega,
                reason,
            })
    }
}

/// The point of the linear time-invariant `model` on `basis` (swept parameter `parameter`)
/// with its error estimate: what the exact piecewise method gives for such a model (its
/// harmonics are exact, nothing lies above H), by one solve per harmonic. `None` where the
/// shortcut does not apply.
pub(super) fn exact_point(
    model: &Model,
    basis: HarmonicBasis,
    parameter: f64,
) -> Result<Option<NewPoint>> {
    if !model.is_linear_time_invariant() || model.n_dofs() > Model::MAX_DENSE_DOFS {
        return Ok(None);
    }
    // Not built (a load above H, which the exact method takes): the exact method decides.
    let Ok(hb) = HarmonicBalance::with_formulation(model, basis, Formulation::Full) else {
        return Ok(None);
    };
    let Some(solution) = solve_time_invariant(&hb) else {
        return Ok(None);
    };
    let mut point =
        point_of(model, &solution, parameter).map_err(|reason| crate::Error::Solver { reason })?;
    point.estimate = Some(time_invariant_estimate(&hb, &solution)?);
    Ok(Some(point))
}

/// The speeds in `(from, to)` (in the sweep's order) where a loaded order `k` meets a damped
/// natural frequency `ω_d = Im λ` of the state matrix, `Ω = ω_d / k`, with the half-power
/// points `Ω ± |Re λ| / k` beside it: every resonance gets points, however narrow.
fn resonances(model: &Model, from: f64, to: f64) -> Result<Vec<f64>> {
    let Some(lambdas) = crate::stability::state_eigenvalues(model)? else {
        return Ok(Vec::new());
    };
    let mut orders: Vec<usize> = model
        .loads()
        .iter()
        .filter(|l| l.order > 0 && !l.is_zero())
        .map(|l| l.order)
        .collect();
    orders.sort_unstable();
    orders.dedup();
    let (lo, hi) = (from.min(to), from.max(to));
    let mut out: Vec<f64> = lambdas
        .iter()
        .filter(|l| l.im > 0.0)
        .flat_map(|l| {
            orders.iter().flat_map(move |&k| {
                let (w, width) = (l.im / k as f64, l.re.abs() / k as f64);
                [w - width, w, w + width]
            })
        })
        .filter(|w| *w > lo && *w < hi)
        .collect();
    out.sort_by(f64::total_cmp);
    if to < from {
        out.reverse();
    }
    Ok(out)
}

/// The branch point of `solution` (swept parameter `parameter`).
fn point_of(
    model: &Model,
    solution: &crate::Solution,
    parameter: f64,
) -> std::result::Result<NewPoint, String> {
    NewPoint::new(
        model,
        *solution.basis(),
        solution.harmonics().to_vec(),
        parameter,
        solution.residual(),
    )
}

/// The solution at `omega` (`None` where the shortcut does not apply).
fn sample(hb: &mut HarmonicBalance, ws: &mut Workspace, omega: f64) -> Result<Option<Sample>> {
    hb.set_omega(omega)?;
    let Some(solution) = solve_time_invariant(hb) else {
        return Ok(None);
    };
    let mut x = vec![0.0; hb.layout().len()];
    hb.layout().pack(solution.harmonics(), &mut x);
    let slope = omega_slope(hb, &x, ws)?;
    Ok(Some(Sample {
        omega,
        x,
        slope,
        solution,
    }))
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

/// The angle between `a` and `b`.
fn angle(a: &[f64], b: &[f64]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(p, q)| p * q).sum();
    (dot / (norm(a) * norm(b)).max(f64::MIN_POSITIVE))
        .clamp(-1.0, 1.0)
        .acos()
}
