//! Kink crossings of the exponential flow ([`exponential`](super::exp_flow)): the elements'
//! `(u, u̇)` at the end of every sub-step, the first crossing inside it from the cubic Hermite
//! interpolant ([`Pieces::crossing`](crate::stability::integrated::pieces::Pieces::crossing)), its time by Newton on
//! the Taylor series of the exact solution, and the saltation factor of the force jump there.

use super::exp_flow::ExpFlow;
use super::kernels::gemv;
use crate::stability::integrated::pieces::{stays_inside, widened, Pieces};
use crate::stability::system::Coordinates;
use nalgebra::{DMatrix, DVector};

/// The elements with kinks and the rows that give their `(u, u̇)` from the scaled state.
pub(crate) struct Kinked {
    pub(crate) elements: Vec<usize>,
    /// `2K × 2n`: row `2j` is `s_q w̃_e` on the positions, row `2j + 1` is `s_v w̃_e` on the
    /// rates, for the `j`-th element with kinks `e`.
    pub(crate) rows: DMatrix<f64>,
    /// The current piece's edges of each, [`widened`] by the crossing's tolerance: a sub-step
    /// whose `u` stays inside needs no closer look.
    bounds: Vec<(f64, f64)>,
}

impl Kinked {
    /// The elements of `sys` with a kink in `has_kinks`, scales `s_q`, `s_v`.
    pub(crate) fn new(
        sys: &Coordinates,
        has_kinks: impl Fn(usize) -> bool,
        scale_q: f64,
        scale_v: f64,
    ) -> Self {
        let n = sys.len();
        let elements: Vec<usize> = (0..sys.weights.len()).filter(|&e| has_kinks(e)).collect();
        let mut rows = DMatrix::zeros(2 * elements.len(), 2 * n);
        for (j, &e) in elements.iter().enumerate() {
            for &(i, w) in &sys.weights[e] {
                rows[(2 * j, i)] += scale_q * w;
                rows[(2 * j + 1, n + i)] += scale_v * w;
            }
        }
        let bounds = vec![(f64::NEG_INFINITY, f64::INFINITY); elements.len()];
        Self {
            elements,
            rows,
            bounds,
        }
    }

    /// The edges of every element's current piece in `pieces` (after a crossing or a new
    /// start), [`widened`] as [`Pieces::crossing`] widens them.
    pub(crate) fn refresh(&mut self, pieces: &Pieces, scale_q: f64) {
        for (b, &e) in self.bounds.iter_mut().zip(&self.elements) {
            let (lo, hi) = pieces.interval(e);
            *b = widened(lo, hi, scale_q);
        }
    }
}

impl ExpFlow<'_, '_> {
    /// `(u, u̇)` of element `e` at the scaled state `x̃`.
    pub(crate) fn element_state(&self, e: usize, x: &DVector<f64>) -> (f64, f64) {
        let n = self.n;
        let sys = self.sys;
        (
            self.scale_q * sys.gather(e, &x.as_slice()[..n]),
            self.scale_v * sys.gather(e, &x.as_slice()[n..]),
        )
    }

    /// `(u_j, u̇_j)` of the elements with kinks at the scaled state `x̃`, interleaved in
    /// `out` (`2K` values): one product with the rows `(s_q w̃_e, 0)`, `(0, s_v w̃_e)`.
    pub(crate) fn kink_states(&self, x: &DVector<f64>, out: &mut [f64]) {
        if !out.is_empty() {
            gemv(&self.kinks.rows, x.as_slice(), out, false);
        }
    }

    /// The earliest kink crossing over a time `h` with the kinked elements' `(u, u̇)` going
    /// from `start` to `end` ([`ExpFlow::kink_states`]): `(fraction, element, upwards?)`.
    pub(crate) fn first_crossing(
        &self,
        start: &[f64],
        end: &[f64],
        h: f64,
    ) -> Option<(f64, usize, bool)> {
        let mut best: Option<(f64, usize, bool)> = None;
        let pairs = start.chunks_exact(2).zip(end.chunks_exact(2));
        let elements = self.kinks.elements.iter().zip(&self.kinks.bounds);
        for ((&e, &edges), (a, b)) in elements.zip(pairs) {
            let (u0, du0, u1, du1) = (a[0], a[1], b[0], b[1]);
            // Inside the widened edges with the interpolant's largest overshoot: no crossing.
            if stays_inside((u0, u1, du0, du1), h, edges) {
                continue;
            }
            if let Some((s, up)) = self.pieces.crossing(e, u0, u1, du0, du1, h, self.scale_q) {
                if best.is_none_or(|(b, _, _)| s < b) {
                    best = Some((s, e, up));
                }
            }
        }
        best
    }

    /// The time `τ <= h` after the expansion point at which element `e`'s `u` reaches the
    /// edge of its piece (Newton from `guess`); `x` becomes the state there.
    pub(crate) fn locate(
        &self,
        x: &mut DVector<f64>,
        guess: f64,
        h: f64,
        e: usize,
        up: bool,
    ) -> f64 {
        let (lo, hi) = self.pieces.interval(e);
        let edge = if up { hi } else { lo };
        let mut tau = guess;
        for _ in 0..12 {
            self.taylor.evaluate(tau, x);
            let (u, du) = self.element_state(e, x);
            let g = u - edge;
            if g.abs() <= 1e-14 * (edge.abs() + self.scale_q) || du == 0.0 {
                return tau;
            }
            tau = (tau - g / du).clamp(1e-3 * guess, h);
        }
        self.taylor.evaluate(tau, x);
        tau
    }

    /// Moves element `e` across its kink at angle `theta` with the scaled state `x̃`: the
    /// factor of the saltation matrix of its force jump ([`Pieces::cross_jump`](crate::stability::integrated::pieces::Pieces::cross_jump)).
    pub(crate) fn cross(
        &mut self,
        e: usize,
        up: bool,
        theta: f64,
        x: &DVector<f64>,
    ) -> Option<f64> {
        let (u, du) = self.element_state(e, x);
        let omega_s = self.scale_v / self.scale_q;
        self.pieces
            .cross_jump(self.sys, e, up, (theta, u, du), omega_s)
    }
}
