//! The phasors `e^{-ilθ}` at a piece's two ends for `l = 0, 1, 2, ...`, by recurrence: the
//! harmonics of a piece need them for every order, and two trigonometric calls per order and
//! window were most of the solve.

use num_complex::Complex64;
use std::f64::consts::TAU;

/// Orders after which the recurrence is anchored again on a direct evaluation (its rounding
/// grows like the number of steps: below 1e-14 here).
const ANCHOR: usize = 64;

/// `e^{-ila}`, `e^{-ilb}` of a piece `[a, b)` at the current order `l`, and `e^{ika}`,
/// `e^{ikb}` for the load orders `k = 0..=K`.
pub(super) struct EdgePhasors {
    a: f64,
    b: f64,
    l: usize,
    /// `e^{-ila}`.
    pub(super) ea: Complex64,
    /// `e^{-ilb}`.
    pub(super) eb: Complex64,
    step_a: Complex64,
    step_b: Complex64,
    ka: Vec<Complex64>,
    kb: Vec<Complex64>,
}

impl EdgePhasors {
    /// At order 0, with the load orders up to `orders`.
    pub(super) fn new(a: f64, b: f64, orders: usize) -> Self {
        let at = |x: f64, k: usize| Complex64::from_polar(1.0, k as f64 * x);
        Self {
            a,
            b,
            l: 0,
            ea: Complex64::new(1.0, 0.0),
            eb: Complex64::new(1.0, 0.0),
            step_a: at(-a, 1),
            step_b: at(-b, 1),
            ka: (0..=orders).map(|k| at(a, k)).collect(),
            kb: (0..=orders).map(|k| at(b, k)).collect(),
        }
    }

    /// Moves to order `l` (the next one, or anywhere by direct evaluation).
    pub(super) fn go_to(&mut self, l: usize) {
        if l == self.l + 1 && l % ANCHOR != 0 {
            self.ea *= self.step_a;
            self.eb *= self.step_b;
        } else if l != self.l {
            self.ea = Complex64::from_polar(1.0, -(l as f64) * self.a);
            self.eb = Complex64::from_polar(1.0, -(l as f64) * self.b);
        }
        self.l = l;
    }

    /// `W(l - k) = (1/2π) ∫_a^b e^{-i(l-k)θ} dθ` at the current `l`, for a load order
    /// `k` in `-K..=K`.
    pub(super) fn window(&self, k: i64) -> Complex64 {
        let j = self.l as i64 - k;
        if j == 0 {
            return Complex64::new((self.b - self.a) / TAU, 0.0);
        }
        let (ka, kb) = if k >= 0 {
            (self.ka[k as usize], self.kb[k as usize])
        } else {
            (self.ka[(-k) as usize].conj(), self.kb[(-k) as usize].conj())
        };
        (self.ea * ka - self.eb * kb) / Complex64::new(0.0, TAU * j as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_recurrence_keeps_to_the_direct_evaluation() {
        let (a, b) = (0.3, 2.9);
        let mut p = EdgePhasors::new(a, b, 2);
        // Against the direct evaluation, whose own argument `l b` carries a rounding of
        // ε l b: the recurrence adds at most 64 steps' rounding to an anchor's.
        let mut worst: f64 = 0.0;
        for l in 0..5000 {
            p.go_to(l);
            let direct = |x: f64| Complex64::from_polar(1.0, -(l as f64) * x);
            let allowed = 1e-14 + 4.0 * f64::EPSILON * l as f64 * b;
            let e = (p.ea - direct(a)).norm().max((p.eb - direct(b)).norm());
            worst = worst.max(e / allowed);
            for k in [-2i64, 0, 1, 2] {
                let j = l as f64 - k as f64;
                let want = if j == 0.0 {
                    Complex64::new((b - a) / TAU, 0.0)
                } else {
                    (Complex64::from_polar(1.0, -j * a) - Complex64::from_polar(1.0, -j * b))
                        / Complex64::new(0.0, TAU * j)
                };
                worst = worst.max((p.window(k) - want).norm() / allowed);
            }
        }
        assert!(worst < 1.0, "{worst:e} of the allowed rounding");
    }
}
