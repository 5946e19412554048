//! Where an element coordinate crosses a contact edge: the crossings of the kinks between
//! samples (and the grazings inside one interval), by Newton on the coordinate's series
//! started from the cubic through the samples and their slopes.

use super::derivatives;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Where the element coordinate crosses a kink: the kink `κ`, the angle `θ*` (on the
/// fundamental, in `[0, 2π)` up to rounding), the sample interval `j` with
/// `θ_j <= θ* <= θ_{j+1}` and the slope `u'(θ*)` (per radian of θ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeCrossing {
    /// The kink `κ` crossed.
    pub kappa: f64,
    /// `θ*`.
    pub theta: f64,
    /// The sample interval `j`.
    pub sample: usize,
    /// `u'(θ*)`.
    pub slope: f64,
}

/// The crossings of the kinks `kinks` by the element coordinate with samples `u` and `du`
/// (its time derivative) at `θ_j = 2π j / N` and harmonics `uk`, appended to `out`.
/// `fundamental` is the Ω/ν that turns θ-derivatives into time derivatives.
///
/// A crossing shows as a change of side between two samples; two crossings inside one sample
/// interval (the coordinate grazes the edge and comes back) show as an extremum there (`du`
/// changes sign) beyond the edge, and are found as well, so the residual stays continuous when
/// a contact opens or closes between samples.
pub fn find_edge_crossings(
    kinks: &[f64],
    u: &[f64],
    du: &[f64],
    uk: &[Complex64],
    fundamental: f64,
    out: &mut Vec<EdgeCrossing>,
) {
    let n = u.len();
    let h = TAU / n as f64;
    let mut push = |kappa: f64, theta: f64, sample: usize| {
        let slope = derivatives(uk, theta)[1];
        out.push(EdgeCrossing {
            kappa,
            theta,
            sample,
            slope,
        });
    };
    // Between samples `u` moves at most `h max |u_θ| ≤ h Σ k |u_k|`: a kink outside the
    // samples' range by more is neither crossed nor grazed.
    let (lowest, highest) = u
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, m), &x| {
            (l.min(x), m.max(x))
        });
    let (mut reach, mut quartic) = (0.0, 0.0);
    for (k, c) in uk.iter().enumerate() {
        let (kf, a) = (k as f64, c.norm_sqr().sqrt());
        reach += kf * a;
        quartic += kf * kf * kf * kf * a;
    }
    reach *= h;
    // The cubic through two samples and their slopes is off by at most `h⁴ max|u⁗| / 384`.
    quartic *= h.powi(4) / 384.0;
    for &kappa in kinks {
        if kappa < lowest - reach || kappa > highest + reach {
            continue;
        }
        // The scan is most of the cost where nothing is crossed: no division (modulo) and no
        // conversion per sample.
        let (mut b, mut vb) = (u[0] - kappa, du[0]);
        for j in 0..n {
            let next = if j + 1 == n { 0 } else { j + 1 };
            // Sides as the laws draw them: `u > κ` above, `u = κ` below (a sample on the edge
            // belongs to the side below, so the crossing is still seen).
            let (a, va) = (b, vb);
            (b, vb) = (u[next] - kappa, du[next]);
            let cubic = Hermite::new(a, b, va / fundamental * h, vb / fundamental * h);
            if (a > 0.0) != (b > 0.0) {
                let (lo, hi) = (j as f64 * h, (j + 1) as f64 * h);
                let t = root(uk, kappa, lo, hi, a > 0.0, lo + h * cubic.root());
                push(kappa, t, j);
                continue;
            }
            if va * vb >= 0.0 {
                continue;
            }
            // An extremum inside: can it reach the edge? (The cubic's extremum, to its error.)
            let (lo, hi) = (j as f64 * h, (j + 1) as f64 * h);
            let (s, peak) = cubic.extremum();
            if (a > 0.0 && peak > quartic) || (a <= 0.0 && peak < -quartic) {
                continue;
            }
            let te = extremum(uk, lo, hi, va > 0.0, lo + h * s);
            let e = derivatives(uk, te)[0] - kappa;
            if (e > 0.0) != (a > 0.0) {
                let t1 = root(uk, kappa, lo, te, a > 0.0, 0.5 * (lo + te));
                let t2 = root(uk, kappa, te, hi, e > 0.0, 0.5 * (te + hi));
                push(kappa, t1, j);
                push(kappa, t2, j);
            }
        }
    }
}

/// The cubic `p(s)`, `s ∈ [0, 1]`, with `p(0) = a`, `p(1) = b`, `p'(0) = da`, `p'(1) = db`.
struct Hermite([f64; 4]);

impl Hermite {
    fn new(a: f64, b: f64, da: f64, db: f64) -> Self {
        Self([
            a,
            da,
            3.0 * (b - a) - 2.0 * da - db,
            2.0 * (a - b) + da + db,
        ])
    }

    fn value(&self, s: f64) -> (f64, f64) {
        let [c0, c1, c2, c3] = self.0;
        (
            ((c3 * s + c2) * s + c1) * s + c0,
            (3.0 * c3 * s + 2.0 * c2) * s + c1,
        )
    }

    /// Where `p` changes sign in `[0, 1]` (given it does): a start for the series' root.
    fn root(&self) -> f64 {
        let [a, ..] = self.0;
        let b = self.value(1.0).0;
        let mut s = (a / (a - b)).clamp(0.0, 1.0);
        for _ in 0..3 {
            let (p, dp) = self.value(s);
            let next = s - p / dp;
            if !(0.0..=1.0).contains(&next) {
                break;
            }
            s = next;
        }
        s
    }

    /// Its extremum in `[0, 1]` (given `p'` changes sign there): `(s, p(s))`.
    fn extremum(&self) -> (f64, f64) {
        let [_, c1, c2, c3] = self.0;
        // p'(s) = c1 + 2 c2 s + 3 c3 s² = 0, the root inside [0, 1].
        let (qa, qb, qc) = (3.0 * c3, 2.0 * c2, c1);
        let s = if qa.abs() <= 1e-12 * (qb.abs() + qc.abs()) {
            -qc / qb
        } else {
            let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
            let q = -0.5 * (qb + qb.signum() * disc);
            let (r1, r2) = (q / qa, qc / q);
            if (0.0..=1.0).contains(&r1) {
                r1
            } else {
                r2
            }
        };
        let s = if s.is_finite() {
            s.clamp(0.0, 1.0)
        } else {
            0.5
        };
        (s, self.value(s).0)
    }
}

/// The root of `u(θ) = κ` in `[lo, hi]` (the side at `lo` is `lo_above`), from `t`.
fn root(uk: &[Complex64], kappa: f64, lo: f64, hi: f64, lo_above: bool, t: f64) -> f64 {
    let tol = 1e-14 * (1.0 + kappa.abs());
    bracketed_newton(lo, hi, t, lo_above, tol, |t| {
        let d = derivatives(uk, t);
        (d[0] - kappa, d[1])
    })
}

/// The extremum of `u` in `[lo, hi]`, where `u'` changes sign (positive at `lo` if
/// `rising`), from `t`.
fn extremum(uk: &[Complex64], lo: f64, hi: f64, rising: bool, t: f64) -> f64 {
    bracketed_newton(lo, hi, t, rising, 0.0, |t| {
        let d = derivatives(uk, t);
        (d[1], d[2])
    })
}

/// The zero of `g` in `[lo, hi]` (`g > 0` at `lo` if `lo_positive`), by Newton from `t` with
/// `f(t) = (g, g')`, kept inside the shrinking bracket (bisection where a step leaves it);
/// stops at `|g| <= tol` or a step of 1e-15 of a period.
pub(crate) fn bracketed_newton(
    mut lo: f64,
    mut hi: f64,
    t: f64,
    lo_positive: bool,
    tol: f64,
    f: impl Fn(f64) -> (f64, f64),
) -> f64 {
    let mut t = t.clamp(lo, hi);
    for _ in 0..60 {
        let (g, slope) = f(t);
        if g.abs() <= tol {
            break;
        }
        if (g > 0.0) == lo_positive {
            lo = t;
        } else {
            hi = t;
        }
        let next = t - g / slope;
        let next = if next >= lo && next <= hi && next.is_finite() {
            next
        } else {
            0.5 * (lo + hi)
        };
        let moved = (next - t).abs();
        t = next;
        if moved <= 1e-15 * TAU {
            break;
        }
    }
    t
}
