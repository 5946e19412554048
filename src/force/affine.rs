//! Whether a law is affine on its pieces, `f = f0 + k u + d u̇` with constant `(f0, k, d)`
//! between its time jumps ([`ForceLaw::time_breakpoints`]) and its kinks
//! ([`ForceLaw::kinks`]): the laws whose harmonics the AFT computes exactly across contact
//! edges ([`crate::harmonic::kinks::exact`]) and whose flow the Floquet analysis integrates
//! exactly ([`crate::stability`]).
//!
//! The force-law interface does not say so; it is tested on samples. On every time segment
//! of the law (two angles inside it) and every interval between its kinks (three values of `u`
//! spread over the interval, or over the given amplitude of `u` where the interval is
//! unbounded, and three of `u̇` over the amplitude of `u̇`) the derivatives must be the same
//! and the force must lie on the plane through the first sample, to 1e-9 relative. Users of
//! the answer check it again along the orbit.

use super::ForceLaw;
use std::f64::consts::TAU;

/// `true` if `law` is affine with constant coefficients on each piece between its time jumps
/// and kinks, tested over `|u| <= amplitude_u`, `|u̇| <= amplitude_du` (module documentation).
pub(crate) fn affine_law(law: &dyn ForceLaw, amplitude_u: f64, amplitude_du: f64) -> bool {
    let mut breaks: Vec<f64> = law
        .time_breakpoints()
        .into_iter()
        .filter(|t| t.is_finite())
        .map(|t| t.rem_euclid(TAU))
        .collect();
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let segments: Vec<(f64, f64)> = if breaks.is_empty() {
        vec![(0.0, TAU)]
    } else {
        (0..breaks.len())
            .map(|i| {
                let a = breaks[i];
                let b = breaks.get(i + 1).copied().unwrap_or(breaks[0] + TAU);
                (a, b)
            })
            .collect()
    };
    let mut kinks: Vec<f64> = law.kinks().into_iter().filter(|k| k.is_finite()).collect();
    kinks.sort_by(f64::total_cmp);
    kinks.dedup();
    let largest_kink = kinks.iter().fold(0.0_f64, |m, k| m.max(k.abs()));
    let a = positive(amplitude_u.max(largest_kink));
    let b = positive(amplitude_du);
    let mut edges = vec![f64::NEG_INFINITY];
    edges.extend(&kinks);
    edges.push(f64::INFINITY);
    let rates = [-0.6 * b, 0.3 * b, 1.2 * b];
    edges.windows(2).all(|w| {
        let (lo, hi) = (w[0], w[1]);
        let us = match (lo.is_finite(), hi.is_finite()) {
            (true, true) => [0.2, 0.55, 0.9].map(|s| lo + s * (hi - lo)),
            (false, true) => [0.3, 1.0, 2.5].map(|s| hi - s * a),
            (true, false) => [0.3, 1.0, 2.5].map(|s| lo + s * a),
            (false, false) => [-0.7, 0.2, 1.5].map(|s| s * a),
        };
        segments.iter().all(|&(t0, t1)| {
            let th = [t0 + 0.31 * (t1 - t0), t0 + 0.73 * (t1 - t0)].map(|t| t.rem_euclid(TAU));
            let points = [
                (th[0], us[0], rates[0]),
                (th[1], us[1], rates[1]),
                (th[0], us[2], rates[1]),
                (th[1], us[0], rates[2]),
            ];
            let (t, u, du) = points[0];
            let f = law.force(t, u, du);
            let (k, d) = law.derivatives(t, u, du);
            points[1..].iter().all(|&(t1, u1, du1)| {
                let f1 = law.force(t1, u1, du1);
                let (k1, d1) = law.derivatives(t1, u1, du1);
                let plane = f + k * (u1 - u) + d * (du1 - du);
                let size = f.abs() + f1.abs() + (k * u1).abs() + (d * du1).abs();
                [f, f1, k, k1, d, d1].iter().all(|v| v.is_finite())
                    && (k1 - k).abs() <= 1e-9 * k.abs().max(k1.abs())
                    && (d1 - d).abs() <= 1e-9 * d.abs().max(d1.abs())
                    && (f1 - plane).abs() <= 1e-9 * size
            })
        })
    })
}

fn positive(x: f64) -> f64 {
    if x > 0.0 && x.is_finite() {
        x
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::{
        Backlash, CubicSpring, LinearSpring, MeshDamping, MeshProfile, MeshStiffness,
    };

    #[test]
    fn contacts_and_springs_are_affine_a_cubic_spring_is_not() {
        let rectangular = MeshProfile::Rectangular {
            one_tooth: 2.0e8,
            two_tooth: 3.5e8,
            contact_ratio: 1.4,
        };
        assert!(affine_law(&LinearSpring::new(3.0, 0.1), 1.0, 1.0));
        assert!(affine_law(
            &Backlash::new(0.5, rectangular.clone()),
            1.0,
            1.0
        ));
        let mesh = |p: MeshProfile| MeshStiffness::new(12, p, MeshDamping::Proportional(1e-5));
        assert!(affine_law(&mesh(rectangular), 1e-5, 1e-2));
        // A stiffness that varies inside the mesh cycle is not.
        let cosine = MeshProfile::Cosine {
            mean: 3e8,
            amplitude: 5e7,
        };
        assert!(!affine_law(&mesh(cosine), 1e-5, 1e-2));
        assert!(!affine_law(&CubicSpring::new(1.0, 0.5), 1.0, 1.0));
        assert!(!affine_law(&CubicSpring::new(1.0, 0.5), 1e-2, 1e-2));
        // Over amplitudes where α u² is 5e-13 of k the spring is affine to the test's 1e-9.
        assert!(affine_law(&CubicSpring::new(1.0, 0.5), 1e-6, 1e-6));
    }
}
