//! The cubic Hermite interpolant of an element coordinate over one step, for the kink
//! crossings of both flows ([`Pieces::crossing`](super::pieces::Pieces::crossing)): its
//! monotone pieces and the first point at an edge.

/// The cubic Hermite interpolant over a step as `p(s) = d + c s + b s² + a s³`, `s ∈ [0, 1]`,
/// from the values `u0`, `u1` and the scaled rates `hd0 = h u̇0`, `hd1 = h u̇1`:
/// `a = 2(u0 - u1) + hd0 + hd1`, `b = 3(u1 - u0) - 2 hd0 - hd1`, `c = hd0`, `d = u0`.
pub(crate) struct Cubic {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
}

impl Cubic {
    pub(crate) fn new(u0: f64, u1: f64, hd0: f64, hd1: f64) -> Self {
        Self {
            a: 2.0 * (u0 - u1) + hd0 + hd1,
            b: 3.0 * (u1 - u0) - 2.0 * hd0 - hd1,
            c: hd0,
            d: u0,
        }
    }

    fn value(&self, s: f64) -> f64 {
        ((self.a * s + self.b) * s + self.c) * s + self.d
    }

    fn rate(&self, s: f64) -> f64 {
        (3.0 * self.a * s + 2.0 * self.b) * s + self.c
    }

    /// The ends of the pieces of `[0, 1]` on which the cubic is monotone: the roots in
    /// `(0, 1)` of `p'(s) = 3a s² + 2b s + c`, then 1.
    pub(crate) fn monotone_pieces(&self) -> impl Iterator<Item = f64> {
        let (a, b, c) = (self.a, self.b, self.c);
        let (mut r1, mut r2) = (f64::NAN, f64::NAN);
        let disc = b * b - 3.0 * a * c;
        if disc >= 0.0 {
            // The stable pair of roots of 3a s² + 2b s + c.
            let q = -(b + b.signum() * disc.sqrt());
            if q != 0.0 {
                r1 = q / (3.0 * a);
                r2 = c / q;
            } else if a != 0.0 {
                r1 = 0.0;
            }
        }
        if r1 > r2 {
            std::mem::swap(&mut r1, &mut r2);
        }
        [r1, r2]
            .into_iter()
            .filter(|r| *r > 0.0 && *r < 1.0)
            .chain(std::iter::once(1.0))
    }

    /// The first `s` in `[lo, hi]` (a monotone piece with `p(hi)` at or beyond `edge`, beyond
    /// meaning above if `up`) with `p(s)` at or beyond `edge`: `lo` if `p(lo)` is already
    /// there, else Newton on `p(s) = edge` kept inside the bracket (bisection where it would
    /// leave it), then bisection to the nearest point at or beyond. Always in `[lo, hi]`.
    pub(crate) fn first_at(&self, edge: f64, up: bool, lo: f64, hi: f64) -> f64 {
        let sense = if up { 1.0 } else { -1.0 };
        let g = |s: f64| sense * (self.value(s) - edge);
        // |g| at this level is rounding.
        let noise = 8.0
            * f64::EPSILON
            * (self.a.abs() + self.b.abs() + self.c.abs() + self.d.abs() + edge.abs());
        let (mut a, mut b) = (lo, hi);
        let (ga, gb) = (g(a), g(b));
        if ga >= 0.0 {
            // Already at or beyond the edge (within the crossing's tolerance band).
            return a;
        }
        let secant = a + (b - a) * (-ga / (gb - ga));
        let mut x = if secant > a && secant < b {
            secant
        } else {
            0.5 * (a + b)
        };
        for _ in 0..100 {
            let gx = g(x);
            if gx >= 0.0 {
                b = x;
            } else {
                a = x;
            }
            if gx.abs() <= noise || b - a <= 2.0 * f64::EPSILON * b {
                break;
            }
            let newton = x - gx / (sense * self.rate(x));
            x = if newton > a && newton < b {
                newton
            } else {
                0.5 * (a + b)
            };
        }
        if g(x) >= 0.0 {
            return x;
        }
        // Just short of the edge: bisection between there and the bracket's outer end.
        let mut a = x;
        for _ in 0..60 {
            let mid = 0.5 * (a + b);
            if g(mid) >= 0.0 {
                b = mid;
            } else {
                a = mid;
            }
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Newton in the bracket finds a point at or beyond the edge where the cubic is at the edge
    /// to rounding, as bisection to the last bit does (the same point where the root is well
    /// conditioned), on both edges and on cubics that turn inside the step.
    #[test]
    fn newton_in_the_bracket_matches_bisection() {
        for k in 0..200 {
            let t = k as f64;
            let (u0, u1) = ((0.37 * t).sin(), (1.1 * t).cos());
            let (hd0, hd1) = (2.0 * (0.71 * t).sin(), 2.0 * (0.29 * t).cos());
            let cubic = Cubic::new(u0, u1, hd0, hd1);
            let mut lo = 0.0;
            for hi in cubic.monotone_pieces() {
                let (va, vb) = (cubic.value(lo), cubic.value(hi));
                let (edge, up) = (0.5 * (va + vb), vb > va);
                if va != vb {
                    let sense = if up { 1.0 } else { -1.0 };
                    let (mut a, mut b) = (lo, hi);
                    for _ in 0..200 {
                        let mid = 0.5 * (a + b);
                        if sense * (cubic.value(mid) - edge) >= 0.0 {
                            b = mid;
                        } else {
                            a = mid;
                        }
                    }
                    let s = cubic.first_at(edge, up, lo, hi);
                    // The rounding of the cubic's value, and what it leaves of the root.
                    let size = cubic.a.abs() + cubic.b.abs() + cubic.c.abs() + cubic.d.abs();
                    let noise = 16.0 * f64::EPSILON * (size + edge.abs());
                    let miss = cubic.value(s) - edge;
                    assert!(sense * miss >= 0.0 && miss.abs() <= noise, "{k}: {miss}");
                    let slope = cubic.rate(b).abs().max(1e-3);
                    assert!((s - b).abs() <= 2.0 * noise / slope, "{k}: {s} {b}");
                }
                lo = hi;
            }
        }
    }

    /// A step that starts inside the crossing's tolerance band, beyond the bare edge: the
    /// crossing is at its start, never before it (the secant through both ends would reach
    /// back to s = -0.5 or -50).
    #[test]
    fn a_start_beyond_the_edge_is_the_crossing() {
        let (edge, tol) = (1.0, 1e-13);
        for (u0, u1) in [
            (edge + 0.5 * tol, edge + 1.5 * tol),
            (edge + 0.99 * tol, edge + 1.01 * tol),
        ] {
            let cubic = Cubic::new(u0, u1, u1 - u0, u1 - u0);
            for (lo, hi) in [(0.0, 1.0), (0.25, 0.75)] {
                let s = cubic.first_at(edge, true, lo, hi);
                assert_eq!(s, lo, "{u0} {u1}");
            }
        }
        // Short of the edge at the start, at it at the end: inside the bracket.
        let cubic = Cubic::new(edge - 1e-3, edge + 1e-3, 2e-3, 2e-3);
        let s = cubic.first_at(edge, true, 0.0, 1.0);
        assert!((0.0..=1.0).contains(&s) && (s - 0.5).abs() < 1e-12, "{s}");
    }
}
