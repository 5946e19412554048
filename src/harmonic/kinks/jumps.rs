//! The jumps of a force along an orbit where it crosses a contact edge: the one-sided
//! difference `D = F₊ - F₋` of the law's smooth pieces and its derivatives along the orbit
//! (module documentation of [`super`]).

use super::Crossing;
use crate::force::ForceLaw;
use std::f64::consts::TAU;

/// The orbit at a crossing: the angle θ* (of the axis the quadrature runs along), its place
/// `α` in the sample interval, the coordinate `(u, u', u'', u''')` and its rate
/// `(u̇, u̇', u̇'')`, derivatives in θ.
///
/// On one fundamental `u̇ = Ω u'`; along one axis of a torus grid the rate has its own
/// series (the other bases turn too), so it is given separately.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OrbitAt {
    pub theta: f64,
    pub alpha: f64,
    pub u: [f64; 4],
    pub v: [f64; 3],
}

/// `[f]`, `[f']`, `[f'']` in θ along the orbit at its crossing of `kappa`, and the jumps of
/// `∂f/∂u`, `∂f/∂u̇`; `angle(θ)` is the law's own angle at θ, `h` the sample spacing. `None`
/// where a jump is not finite (the crossing is then left uncorrected).
pub(crate) fn jumps(
    law: &dyn ForceLaw,
    kappa: f64,
    orbit: &OrbitAt,
    angle: impl Fn(f64) -> f64,
    h: f64,
) -> Option<Crossing> {
    let (theta, d) = (orbit.theta, orbit.u);
    // One-sided values at κ ± δ, δ a millionth of the coordinate's change over a sample (so
    // the result does not depend on the units of u); the O(δ) slope is taken out below.
    let delta = match 1e-6 * d[1].abs() * h {
        x if x > 0.0 => x,
        _ => 1e-12 * (1.0 + kappa.abs()),
    };
    let [v, v1, v2] = orbit.v;
    // D, D_u, D_v at angle t.
    let diff = |t: f64| {
        let p = angle(t);
        let (ku, kv) = law.derivatives(p, kappa + delta, v);
        let (lu, lv) = law.derivatives(p, kappa - delta, v);
        let d0 =
            law.force(p, kappa + delta, v) - law.force(p, kappa - delta, v) - delta * (ku + lu);
        [d0, ku - lu, kv - lv]
    };
    let eps = 1e-4;
    let (m, c, p) = (diff(theta - eps), diff(theta), diff(theta + eps));
    let dt = |i: usize| (p[i] - m[i]) / (2.0 * eps);
    let dtt = (p[0] - 2.0 * c[0] + m[0]) / (eps * eps);
    let s = d[1].signum();
    let f0 = c[0];
    let f1 = dt(0) + c[1] * d[1] + c[2] * v1;
    let f2 = dtt + 2.0 * dt(1) * d[1] + 2.0 * dt(2) * v1 + c[1] * d[2] + c[2] * v2;
    let c = Crossing {
        theta: theta.rem_euclid(TAU),
        alpha: orbit.alpha,
        slope: d[1],
        jumps: [s * f0, s * f1, s * f2],
        du_jumps: [s * c[1], s * dt(1)],
        ddu_jumps: [s * c[2], s * dt(2)],
    };
    let mut all = c.jumps.iter().chain(&c.du_jumps).chain(&c.ddu_jumps);
    all.all(|v| v.is_finite()).then_some(c)
}
