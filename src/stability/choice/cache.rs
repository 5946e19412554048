//! What a sweep's Floquet analyses carry from one point to the next: one field per method
//! that keeps something (the reduced basis's modes, the exponential flow's generators, the
//! chord steps' Jacobian, the HB orbit's last check, the time-invariant eigenvalues).

use super::orbit_check::OrbitCheck;
use crate::stability::exponential::kept::KeptGenerators;
use crate::stability::large::reduction::ModeCache;
use crate::stability::shooting::chord::KeptJacobian;
use crate::stability::time_invariant::StateEigenvalues;

/// What a sweep's Floquet analyses keep from one point to the next
/// ([`FloquetOptions::compute_with`](crate::stability::FloquetOptions::compute_with)): the undamped modes of the model, the last three orbit
/// corrections (the shooting of the next point starts from the HB state plus their
/// extrapolation in Ω), the last monodromy matrix (the first Jacobian of the next shooting's
/// chord steps) and the sensitivity of the multipliers to the orbit measured by the last
/// shooting that measured it.
#[derive(Debug, Clone, Default)]
pub struct FloquetCache {
    pub(crate) modes: ModeCache,
    /// The exponential flow's generators of the last point.
    pub(crate) generators: KeptGenerators,
    /// The last orbit corrections `(Ω, (δq, δq̇))`, oldest first.
    pub(crate) corrections: Vec<(f64, Vec<f64>)>,
    pub(crate) jacobian: Option<KeptJacobian>,
    pub(crate) kappa: Option<f64>,
    /// How long the last point's analysis took (set by the sweep that owns the cache).
    last_time: Option<std::time::Duration>,
    /// The last measurement of the HB orbit's multipliers against the exact orbit's.
    pub(crate) orbit_check: Option<OrbitCheck>,
    /// The HB orbit's pieces did not apply (laws that are not piecewise affine): the next
    /// points go to the exact orbit directly.
    pub(crate) exact_only: bool,
    /// The state matrix's eigenvalues of a linear time-invariant model.
    pub(crate) time_invariant: Option<StateEigenvalues>,
}

/// Orbit corrections kept for the next point's prediction (a quadratic in Ω).
pub(crate) const PREDICTION_POINTS: usize = 3;

impl FloquetCache {
    /// How long the last point's analysis took, if a sweep recorded it.
    pub(crate) fn last_time(&self) -> Option<std::time::Duration> {
        self.last_time
    }

    /// Records how long the last point's analysis took.
    pub(crate) fn set_last_time(&mut self, time: std::time::Duration) {
        self.last_time = Some(time);
    }

    /// The orbit correction `(δq, δq̇)` (`len` values) predicted at `omega` from the last
    /// ones if the last is within 20 %: their Lagrange polynomial through `(Ω_i, d_i)` (at most
    /// quadratic), over the last points on which the sweep goes on in the same direction by
    /// at most twice its last step (not across a turn of the branch), the last `d` alone
    /// otherwise.
    pub(crate) fn predicted_correction(&self, omega: f64, len: usize) -> Option<Vec<f64>> {
        let (w_last, d_last) = self.corrections.last()?;
        if (omega - w_last).abs() > 0.2 * w_last || d_last.len() != len {
            return None;
        }
        // The longest run of usable points ending at the last one.
        let mut used = 1;
        for k in (0..self.corrections.len() - 1).rev() {
            let (w0, d0) = &self.corrections[k];
            let w1 = self.corrections[k + 1].0;
            let ratio = (omega - w_last) / (w1 - w0);
            let same_way = (w1 - w0) * (omega - w_last) > 0.0;
            if !(same_way && ratio <= 2.0 && d0.len() == len) {
                break;
            }
            used += 1;
        }
        let points = &self.corrections[self.corrections.len() - used..];
        let mut out = vec![0.0; len];
        for (i, (wi, di)) in points.iter().enumerate() {
            let weight: f64 = points
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, (wj, _))| (omega - wj) / (wi - wj))
                .product();
            for (o, d) in out.iter_mut().zip(di) {
                *o += weight * d;
            }
        }
        Some(out)
    }
}
