//! Where each element is relative to its kinks, shared by both flows ([`flow`](super::flow),
//! [`exponential`](crate::stability::exponential::exp_flow)): the law evaluated on the current side of each kink
//! (continued linearly from the one-sided limit where a state strays across), the side from a
//! state, and the first crossing of a kink inside a step from the cubic Hermite interpolant of
//! `u` (values and rates at both ends); the saltation matrix of a force jump at a crossing.

use super::cubic::Cubic;
use super::dopri::hermite;
use crate::stability::system::Coordinates;

/// `side[e] = j` means `kinks[e][j-1] <= u < kinks[e][j]` (open at the ends).
pub(crate) struct Pieces {
    kinks: Vec<Vec<f64>>,
    side: Vec<usize>,
}

impl Pieces {
    /// The finite kinks of every element of the model, sorted, every element below its first.
    pub(crate) fn new(sys: &Coordinates) -> Self {
        let kinks = sys
            .model
            .elements()
            .iter()
            .map(|e| {
                let mut k: Vec<f64> = e
                    .law()
                    .kinks()
                    .into_iter()
                    .filter(|v| v.is_finite())
                    .collect();
                k.sort_by(f64::total_cmp);
                k.dedup();
                k
            })
            .collect::<Vec<_>>();
        let side = vec![0; kinks.len()];
        Self { kinks, side }
    }

    /// `true` if element `e` has a kink.
    pub(crate) fn has_kinks(&self, e: usize) -> bool {
        !self.kinks[e].is_empty()
    }

    /// The kinks of element `e`, sorted.
    pub(crate) fn kinks(&self, e: usize) -> &[f64] {
        &self.kinks[e]
    }

    /// Puts element `e` on the piece just above (`above`) or below its kink `kink`.
    pub(crate) fn place(&mut self, e: usize, kink: f64, above: bool) {
        let below = self.kinks[e].iter().filter(|&&k| k < kink).count();
        self.side[e] = below + usize::from(above);
    }

    /// The open interval of `u` of element `e`'s current piece.
    pub(crate) fn interval(&self, e: usize) -> (f64, f64) {
        let k = &self.kinks[e];
        let j = self.side[e];
        let lo = if j == 0 { f64::NEG_INFINITY } else { k[j - 1] };
        let hi = k.get(j).copied().unwrap_or(f64::INFINITY);
        (lo, hi)
    }

    /// A fixed point inside element `e`'s current interval: its affine coefficients are read
    /// there, so that two visits of the same piece give bit-equal coefficients.
    pub(crate) fn inside(&self, e: usize) -> f64 {
        let (lo, hi) = self.interval(e);
        let away = |edge: f64, dir: f64| {
            if edge * dir < 0.0 {
                0.0
            } else if edge == 0.0 {
                dir
            } else {
                2.0 * edge
            }
        };
        match (lo.is_finite(), hi.is_finite()) {
            (true, true) => 0.5 * (lo + hi),
            (false, true) => away(hi, -1.0),
            (true, false) => away(lo, 1.0),
            (false, false) => 0.0,
        }
    }

    /// Moves element `e` across the upper (`up`) or lower edge of its piece.
    pub(crate) fn cross(&mut self, e: usize, up: bool) {
        if up {
            self.side[e] += 1;
        } else {
            self.side[e] -= 1;
        }
    }

    /// Moves element `e` across its kink at `(θ, u, u̇)` and applies the saltation matrix of a
    /// force jump there to the scaled monodromy matrix `phi` ([`Pieces::cross_jump`],
    /// [`saltation`]; column-major, `2n × 2n`, `mw` = `M⁻¹ w_e`, `omega_s = s_v/s_q`).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn cross_with_saltation(
        &mut self,
        sys: &Coordinates,
        e: usize,
        up: bool,
        at: (f64, f64, f64),
        mw: &[f64],
        omega_s: f64,
        phi: &mut [f64],
    ) {
        if let Some(factor) = self.cross_jump(sys, e, up, at, omega_s) {
            saltation(&sys.weights[e], factor, mw, phi);
        }
    }

    /// Moves element `e` across its kink at `(θ, u, u̇)` and returns the factor
    /// `c = -Δf / (u̇ ω_s)` of the saltation matrix of the force jump `Δf` there: with
    /// `g = w·q - kink` and `F = (q̇, M⁻¹(…))`, `S = I + (F⁺ - F⁻) ∇gᵀ / (∇g·F⁻)` adds
    /// `-M⁻¹ w Δf (wᵀ δq) / u̇` to `δq̇`, scaled `δṽ += c M⁻¹ w (wᵀ δq̃)` (`ω_s = s_v/s_q`).
    /// `None` where the force is continuous. Both sides are evaluated on the kink itself; the
    /// located `u` is not used.
    pub(crate) fn cross_jump(
        &mut self,
        sys: &Coordinates,
        e: usize,
        up: bool,
        (theta, _located, du): (f64, f64, f64),
        omega_s: f64,
    ) -> Option<f64> {
        // Both sides' forces on the kink itself (`g = 0`), not at the located `u`: a law that
        // is continuous there (a backlash edge) then differs by the rounding of its linear
        // continuation alone, where at the located `u`, a rounding away from the kink, the
        // contact side's `k (u - b)` passed for a jump (a rank-one update of Φ̃ per crossing
        // for nothing). The jump is split into its part at rest, judged against that
        // rounding, and its part in `u̇` (contact damping), judged by the damping
        // coefficients alone: it counts however small `u̇` is (its factor `-Δd/ω_s` is not).
        let (lo, hi) = self.interval(e);
        let edge = if up { hi } else { lo };
        let (f0, k0, d0) = self.law(sys, e, theta, edge, du);
        self.cross(e, up);
        let (f1, k1, d1) = self.law(sys, e, theta, edge, du);
        let (rest0, rest1) = (f0 - d0 * du, f1 - d1 * du);
        let rounding = 16.0 * f64::EPSILON * (k0.abs() + k1.abs()) * edge.abs();
        let at_rest = rest1 - rest0;
        let at_rest = if at_rest.abs() <= 1e-9 * rest0.abs().max(rest1.abs()) + rounding {
            0.0
        } else {
            at_rest
        };
        let damping = if (d1 - d0).abs() <= 1e-9 * d0.abs().max(d1.abs()) {
            0.0
        } else {
            (d1 - d0) * du
        };
        let jump = at_rest + damping;
        if jump == 0.0 || du == 0.0 {
            return None;
        }
        Some(-jump / (du * omega_s))
    }

    /// Force and derivatives `(f, ∂f/∂u, ∂f/∂u̇)` of element `e` on its current piece at
    /// `(θ, u, u̇)`.
    pub(crate) fn law(
        &self,
        sys: &Coordinates,
        e: usize,
        theta: f64,
        u: f64,
        du: f64,
    ) -> (f64, f64, f64) {
        let law = sys.model.elements()[e].law();
        let (lo, hi) = self.interval(e);
        if u > lo && u < hi {
            let f = law.force(theta, u, du);
            let (k, d) = law.derivatives(theta, u, du);
            return (f, k, d);
        }
        // Continue the piece linearly from just inside its edge.
        let edge = if u <= lo { lo } else { hi };
        let inside = nudge(edge, if u <= lo { 1.0 } else { -1.0 });
        let f = law.force(theta, inside, du);
        let (k, d) = law.derivatives(theta, inside, du);
        (f + k * (u - inside), k, d)
    }

    /// Sets each element's piece from the positions `q` and rates `v` at the start (on a
    /// kink, the side it is moving to).
    pub(crate) fn init(&mut self, sys: &Coordinates, q: &[f64], v: &[f64]) {
        for ei in 0..sys.weights.len() {
            self.init_element(ei, sys.gather(ei, q), sys.gather(ei, v));
        }
    }

    /// Sets element `e`'s piece from its `(u, u̇)` (on a kink, the side it is moving to).
    pub(crate) fn init_element(&mut self, e: usize, u: f64, du: f64) {
        self.side[e] = self.kinks[e]
            .iter()
            .filter(|&&kv| kv < u || (kv == u && du > 0.0))
            .count();
    }

    /// The first crossing of element `e` out of its piece inside a step of length `h` along
    /// which `u` goes from `u0` (rate `du0`) to `u1` (rate `du1`): `(fraction of the step,
    /// upwards?)`, on the cubic Hermite interpolant: it is monotone between the roots of its
    /// derivative (a quadratic), so the first of those pieces whose end lies outside holds the
    /// first crossing, found by Newton in that bracket ([`Cubic::first_at`]; a crossing
    /// between fixed probes is not missed). A
    /// crossing is counted once `u` is `1e-13 (s_q + |kink|)` beyond the edge.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn crossing(
        &self,
        e: usize,
        u0: f64,
        u1: f64,
        du0: f64,
        du1: f64,
        h: f64,
        scale_q: f64,
    ) -> Option<(f64, bool)> {
        let (lo, hi) = self.interval(e);
        if lo == f64::NEG_INFINITY && hi == f64::INFINITY {
            return None;
        }
        let (low, high) = widened(lo, hi, scale_q);
        if stays_inside((u0, u1, du0, du1), h, (low, high)) {
            return None;
        }
        let outside = |u: f64| -> Option<bool> {
            if u >= high {
                Some(true)
            } else if u <= low {
                Some(false)
            } else {
                None
            }
        };
        let cubic = Cubic::new(u0, u1, h * du0, h * du1);
        let mut prev_s = 0.0;
        for s in cubic.monotone_pieces() {
            let u = if s == 1.0 {
                u1
            } else {
                hermite(u0, u1, du0, du1, h, s)
            };
            if let Some(up) = outside(u) {
                let edge = if up { hi } else { lo };
                return Some((cubic.first_at(edge, up, prev_s, s), up));
            }
            prev_s = s;
        }
        None
    }
}

/// The edges `(lo, hi)` of a piece widened by the crossing's tolerance `1e-13 (s_q + |kink|)`:
/// a crossing is counted once `u` is beyond them.
pub(crate) fn widened(lo: f64, hi: f64, scale_q: f64) -> (f64, f64) {
    let tol = 1e-13 * (scale_q + lo.abs().min(hi.abs()).min(1e300));
    (lo - tol, hi + tol)
}

/// `true` if the cubic Hermite interpolant of `(u0, u1, u̇0, u̇1)` over a step `h` stays
/// strictly inside the widened edges `(low, high)`: it stays within the end values widened by
/// (4/27) h |u̇| at each end (the largest Hermite basis functions for the rates).
pub(crate) fn stays_inside(
    (u0, u1, du0, du1): (f64, f64, f64, f64),
    h: f64,
    (low, high): (f64, f64),
) -> bool {
    let reach = 0.15 * h.abs() * (du0.abs() + du1.abs());
    u0.min(u1) - reach > low && u0.max(u1) + reach < high
}

/// `Φ̃ ← S Φ̃` for the saltation matrix of a force jump of an element with weights `w̃_e`
/// (`weights`) and factor `c` ([`Pieces::cross_jump`]): every column gets
/// `δṽ += c M⁻¹ w_e (w̃_e·δq̃)` (`mw` = `M⁻¹ w_e`, `phi` column-major with `2n` rows).
pub(crate) fn saltation(weights: &[(usize, f64)], factor: f64, mw: &[f64], phi: &mut [f64]) {
    let n = mw.len();
    for col in phi.chunks_exact_mut(2 * n) {
        let wq: f64 = weights.iter().map(|&(i, w)| col[i] * w).sum();
        for (c, m) in col[n..].iter_mut().zip(mw) {
            *c += factor * m * wq;
        }
    }
}

/// A point just inside a kink at `x`, on the side `direction` (±1).
fn nudge(x: f64, direction: f64) -> f64 {
    let step = 4.0 * f64::EPSILON * x.abs().max(f64::MIN_POSITIVE);
    x + direction * step
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crest of the interpolant between the eighths of the step, 1e-9 above the edge, is a
    /// crossing (eight probes saw none); 1e-9 below it is none.
    #[test]
    fn a_crest_between_probes_crosses() {
        let (u0, u1, du0, du1, h) = (0.0, 0.1, 1.0, -0.9, 1.0);
        let fine = (0..=100_000).map(|i| hermite(u0, u1, du0, du1, h, i as f64 * 1e-5));
        let top = fine.fold(f64::NEG_INFINITY, f64::max);
        let probes = (1..=8).map(|p| hermite(u0, u1, du0, du1, h, p as f64 / 8.0));
        let probed = probes.fold(f64::NEG_INFINITY, f64::max);
        assert!(top - probed > 1e-4, "{top} {probed}");
        let at = |edge: f64| {
            let pieces = Pieces {
                kinks: vec![vec![edge]],
                side: vec![0],
            };
            pieces.crossing(0, u0, u1, du0, du1, h, 1e-6)
        };
        let (s, up) = at(top - 1e-9).expect("a crossing");
        assert!(up && (hermite(u0, u1, du0, du1, h, s) - (top - 1e-9)).abs() < 1e-12);
        assert_eq!(at(top + 1e-9), None);
        assert_eq!(at(probed - 1e-9).map(|c| c.1), Some(true));
    }

    /// A backlash edge crossed at a located `u` a rounding away from the kink: no saltation
    /// for the continuous law (its force there, 1.1e-7 N on the contact side, was taken for a
    /// jump), the contact damping's true jump `c u̇` gives one, also at a grazing crossing.
    #[test]
    fn a_saltation_only_where_the_force_jumps() {
        use crate::force::{Backlash, MeshProfile};
        let build = |c: f64| {
            let law = Backlash::new(1.0, MeshProfile::Constant { stiffness: 1e8 })
                .with_contact_damping(c);
            crate::Model::builder(&["x"])
                .mass_diagonal(&[1.0])
                .element("contact", &[("x", 1.0)], law)
                .load("x", 1, 1.0, 0.0)
                .build()
                .unwrap()
        };
        let crossing = |c: f64, du: f64| {
            let model = build(c);
            let sys = Coordinates::full(&model);
            let mut pieces = Pieces::new(&sys);
            // Inside the dead zone (kinks -1, 1), then up across +1 at u = 1 + 1e-15 (the
            // law's force there 1e-7, against k u = 1e8 on the contact side).
            pieces.side[0] = 1;
            let u = 1.0 + 1e-15;
            (
                pieces.cross_jump(&sys, 0, true, (0.0, u, du), 1.0),
                pieces.interval(0),
            )
        };
        let (factor, interval) = crossing(0.0, 2.0);
        assert_eq!(factor, None);
        assert_eq!(interval, (1.0, f64::INFINITY));
        // c u̇ = 0.5 · 2 = 1 N jumps in: S adds -Δf/(u̇ ω_s) = -0.5.
        let (factor, _) = crossing(0.5, 2.0);
        assert!((factor.expect("a jump") + 0.5).abs() < 1e-12, "{factor:?}");
        // Grazing, u̇ = 1e-12: the jump c u̇ is tiny, its factor -c/ω_s is not.
        let (factor, _) = crossing(0.5, 1e-12);
        assert!((factor.expect("a jump") + 0.5).abs() < 1e-12, "{factor:?}");
    }
}
