//! Kink-aware quadrature: the AFT's trapezoid rule corrected at the crossings of a contact edge.
//!
//! The AFT computes `X_k = (1/π) T_k` (`1/2π` for k = 0) from the trapezoid sum
//! `T_k = h Σ_j f(θ_j) e^{-ikθ_j}`, `h = 2π/N`, which is spectrally accurate for a smooth
//! periodic `f`. A contact law makes `f(θ) = F(θ, u(θ), u̇(θ))` only piecewise smooth: where
//! `u` crosses a kink `κ` of the law (a backlash edge) at `θ* = θ_j + α h`, the force or its
//! derivatives jump, and the trapezoid sum is off by (Euler–Maclaurin with a jump, from the
//! multiplication theorem of the Bernoulli polynomials `B_m`)
//!
//! `T - I = [g] h B₁(α) - [g'] h²/2 B₂(α) + [g''] h³/6 B₃(α) - ... = Σ_m (-1)^m [g^(m)] h^{m+1}/(m+1)! B_{m+1}(α)`
//!
//! for an integrand `g` whose value and first two derivatives jump by `[g]`, `[g']`, `[g'']`
//! (right minus left). With `g = f e^{-ikθ}`: `[g] = [f] e_k`, `[g'] = ([f'] - ik[f]) e_k`,
//! `[g''] = ([f''] - 2ik[f'] - k²[f]) e_k`, `e_k = e^{-ikθ*}`. Subtracting it turns the
//! O(1/N²) error of a kink (O(1/N) of a force jump) into O(1/N⁴), at the cost of a few law
//! evaluations per crossing.
//!
//! The jumps of `f` along the orbit come from the law's one-sided values and derivatives at
//! `u = κ ± δ`: with `D = F₊ - F₋` (the difference of the two smooth pieces), `[f] = s D`,
//! `[f'] = s dD/dθ`, `[f''] = s d²D/dθ²` along `(θ, u(θ), u̇(θ))`, `s` the sign of `u'(θ*)`.
//! Second derivatives of `D` in `u`, `u̇` are taken as zero (exact for laws piecewise linear
//! in `u`, `u̇` such as the backlash); its θ-derivatives are finite differences.

use crate::force::ForceLaw;
use num_complex::Complex64;
use std::f64::consts::{PI, TAU};

/// The jumps of the force at one crossing: `θ*` (on the fundamental) and `[f]`, `[f']`,
/// `[f'']` (derivatives in θ), and of its partial derivatives `∂f/∂u`, `∂f/∂u̇` with their
/// first θ-derivative (for the Jacobian, [`correct_spectrum`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// θ* in [0, 2π).
    pub theta: f64,
    /// Its position in its sample interval, `θ* = θ_j + α h`, α in [0, 1] (0 or 1 when it
    /// sits on a sample: the side the sample's value belongs to).
    pub alpha: f64,
    /// `u'(θ*)`: how fast the coordinate crosses (the crossing moves by `-δu/u'`).
    pub slope: f64,
    /// `[f]`, `[f']`, `[f'']`.
    pub jumps: [f64; 3],
    /// `[∂f/∂u]`, `[(∂f/∂u)']`.
    pub du_jumps: [f64; 2],
    /// `[∂f/∂u̇]`, `[(∂f/∂u̇)']`.
    pub ddu_jumps: [f64; 2],
}

/// Terms of the Euler–Maclaurin series kept: `m = 0..ORDERS` (the series in `(kh)^m B_{m+1}`
/// converges for every `k < N`; 11 terms reach 1e-8 of the kink's error at `k = N/4`).
const ORDERS: usize = 11;

/// Bernoulli numbers `B_0 ..= B_11`.
const BERNOULLI: [f64; ORDERS + 1] = [
    1.0,
    -0.5,
    1.0 / 6.0,
    0.0,
    -1.0 / 30.0,
    0.0,
    1.0 / 42.0,
    0.0,
    -1.0 / 30.0,
    0.0,
    5.0 / 66.0,
    0.0,
];

/// Pascal's triangle: `BINOMIAL[n][k] = C(n, k)` for `n <= ORDERS`.
const BINOMIAL: [[f64; ORDERS + 1]; ORDERS + 1] = {
    let mut t = [[0.0; ORDERS + 1]; ORDERS + 1];
    let mut n = 0;
    while n <= ORDERS {
        t[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + if k < n { t[n - 1][k] } else { 0.0 };
            k += 1;
        }
        n += 1;
    }
    t
};

/// `C(n, k)` for `n <= ORDERS`.
fn binomial(n: usize, k: usize) -> f64 {
    BINOMIAL[n][k]
}

/// The Bernoulli polynomials `B_1(a) ..= B_ORDERS(a)` (index m holds `B_{m+1}`), each
/// `B_n(a) = Σ_k C(n, k) B_k a^{n-k}` by Horner's rule in `a`.
fn bernoulli_polynomials(a: f64) -> [f64; ORDERS] {
    let mut out = [0.0; ORDERS];
    for (m, o) in out.iter_mut().enumerate() {
        let n = m + 1;
        // Highest power first: a^n has k = 0.
        *o = (0..=n).fold(0.0, |acc, k| acc * a + BINOMIAL[n][k] * BERNOULLI[k]);
    }
    out
}

/// Subtracts the trapezoid error of every crossing from the AFT harmonics `x[0..=H]` of `N`
/// samples: `Σ_m (-1)^m [g^(m)] h^{m+1}/(m+1)! B_{m+1}(α)` with
/// `[g^(m)] = Σ_{i<=2} C(m, i) [f^(i)] (-ik)^{m-i} e_k` (module documentation; jumps of `f`
/// beyond the second derivative are taken as zero).
pub fn correct_harmonics(x: &mut [Complex64], samples: usize, crossings: &[Crossing]) {
    for c in crossings {
        correct(x, samples, c.theta, c.alpha, &c.jumps, |k| {
            if k == 0 {
                0.5 / PI
            } else {
                1.0 / PI
            }
        });
    }
}

/// Subtracts the trapezoid error of the crossings from the normalised DFT bins
/// `x̂_m = (1/N) Σ_j g_j e^{-imθ_j}`, `m = 0..`, of the samples of `∂f/∂u` (`of_velocity`
/// false) or `∂f/∂u̇` (true): the spectra the Jacobian is assembled from
/// ([`crate::jacobian`]), so that it is the derivative of the corrected residual to the same
/// order (a sampled step costs O(1/N) in the Jacobian).
pub fn correct_spectrum(
    x: &mut [Complex64],
    samples: usize,
    crossings: &[Crossing],
    of_velocity: bool,
) {
    for c in crossings {
        let j = if of_velocity { c.ddu_jumps } else { c.du_jumps };
        correct(x, samples, c.theta, c.alpha, &j, |_| 0.5 / PI);
        // A force jump [f] moves with the crossing, by -δu(θ*)/u'(θ*): in ∂f/∂u a Dirac
        // pulse of weight [f]/u'(θ*) at θ*.
        if !of_velocity && c.jumps[0] != 0.0 && c.slope != 0.0 {
            let w = c.jumps[0] / c.slope * 0.5 / PI;
            let step = Complex64::from_polar(1.0, -c.theta);
            let mut e = Complex64::new(w, 0.0);
            for xm in x.iter_mut() {
                *xm += e;
                e *= step;
            }
        }
    }
}

/// `x[k] -= scale(k) Σ_m (-1)^m [g^(m)] h^{m+1}/(m+1)! B_{m+1}(α)` for `g = f e^{-ikθ}` with
/// the jumps `[f^(i)]` of `jumps` at `theta`.
fn correct(
    x: &mut [Complex64],
    samples: usize,
    theta: f64,
    alpha: f64,
    jumps: &[f64],
    scale: impl Fn(usize) -> f64,
) {
    let h = TAU / samples as f64;
    // (-1)^m h^{m+1} / (m+1)!
    let mut weight = [0.0; ORDERS];
    let mut w = h;
    for (m, wm) in weight.iter_mut().enumerate() {
        *wm = if m % 2 == 0 { w } else { -w };
        w *= h / (m + 2) as f64;
    }
    let b = bernoulli_polynomials(alpha);
    // The error is a polynomial in z = -ik: Σ_p coef[p] z^p, coef[p] = Σ_i [f^(i)]
    // C(p+i, i) weight[p+i] B_{p+i+1}(α).
    let mut coef = [0.0; ORDERS];
    for (p, cp) in coef.iter_mut().enumerate() {
        for (i, f) in jumps.iter().enumerate() {
            let m = p + i;
            if m < ORDERS {
                *cp += f * binomial(m, i) * weight[m] * b[m];
            }
        }
    }
    // z = -ik is imaginary: z^{2j} = (-1)^j k^{2j}, z^{2j+1} = -i (-1)^j k^{2j+1}, so the
    // polynomial is `P(k²) + i k Q(k²)` with real `P`, `Q` (Horner in real arithmetic).
    const EVEN: usize = ORDERS.div_ceil(2);
    let mut even = [0.0; EVEN];
    let mut odd = [0.0; ORDERS / 2];
    for (p, cp) in coef.iter().enumerate() {
        let sign = if (p / 2) % 2 == 0 { 1.0 } else { -1.0 };
        if p % 2 == 0 {
            even[p / 2] = sign * cp;
        } else {
            odd[p / 2] = -sign * cp;
        }
    }
    let step = Complex64::from_polar(1.0, -theta);
    let mut e = Complex64::new(1.0, 0.0);
    for (k, xk) in x.iter_mut().enumerate() {
        let kf = k as f64;
        let k2 = kf * kf;
        let re = even.iter().rev().fold(0.0, |acc, c| acc * k2 + c);
        let im = kf * odd.iter().rev().fold(0.0, |acc, c| acc * k2 + c);
        *xk -= Complex64::new(re, im) * e * scale(k);
        e *= step;
    }
}

/// `(u, u', u'', u''')` at θ of `u(θ) = Re Σ_k U_k e^{ikθ}`.
pub(crate) fn derivatives(uk: &[Complex64], theta: f64) -> [f64; 4] {
    let step = Complex64::from_polar(1.0, theta);
    let mut e = Complex64::new(1.0, 0.0);
    let mut out = [0.0; 4];
    for (k, u) in uk.iter().enumerate() {
        let z = u * e;
        let kf = k as f64;
        out[0] += z.re;
        out[1] -= kf * z.im;
        out[2] -= kf * kf * z.re;
        out[3] += kf * kf * kf * z.im;
        e *= step;
    }
    out
}

/// The crossings of the kinks `kinks` by the element coordinate with samples `u` and `du`
/// (its time derivative) at `θ_j = 2π j / N` and harmonics `uk`, with the jumps of the force
/// of `law` there, appended to `out` (allocates; the AFT calls [`find_edge_crossings`] and
/// [`crossing_jumps`] on its own buffers). `fundamental` is the Ω/ν that turns θ-derivatives
/// into time derivatives, `nu` the ν that turns θ into the law's shaft angle.
#[allow(clippy::too_many_arguments)]
pub fn find_crossings(
    law: &dyn ForceLaw,
    kinks: &[f64],
    u: &[f64],
    du: &[f64],
    uk: &[Complex64],
    fundamental: f64,
    nu: usize,
    out: &mut Vec<Crossing>,
) {
    let mut edges = Vec::new();
    find_edge_crossings(kinks, u, du, uk, fundamental, &mut edges);
    crossing_jumps(law, &edges, uk, fundamental, nu, u.len(), out);
}

/// The jumps of the force of `law` at the crossings `edges` (from [`find_edge_crossings`] on
/// `samples` samples), appended to `out`; crossings where a jump is not finite are left out.
pub fn crossing_jumps(
    law: &dyn ForceLaw,
    edges: &[EdgeCrossing],
    uk: &[Complex64],
    fundamental: f64,
    nu: usize,
    samples: usize,
    out: &mut Vec<Crossing>,
) {
    let h = TAU / samples as f64;
    for e in edges {
        let d = derivatives(uk, e.theta);
        let alpha = ((e.theta - e.sample as f64 * h) / h).clamp(0.0, 1.0);
        let orbit = OrbitAt {
            theta: e.theta,
            alpha,
            u: d,
            v: [fundamental * d[1], fundamental * d[2], fundamental * d[3]],
        };
        let shaft = |t: f64| (nu as f64 * t).rem_euclid(TAU);
        out.extend(jumps(law, e.kappa, &orbit, shaft, h));
    }
}

pub mod exact;
mod jumps;
mod search;
pub(crate) use jumps::{jumps, OrbitAt};
pub(crate) use search::bracketed_newton;
pub use search::{find_edge_crossings, EdgeCrossing};

#[cfg(test)]
mod tests;
