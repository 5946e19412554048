//! Exact harmonics of a law that is affine on its pieces, across contact edges.
//!
//! A contact law such as `gap_contact`, `backlash` (constant or rectangular stiffness) or
//! `stop_spring` is, along an orbit `u(θ) = Re Σ_{k≤H} U_k e^{ikθ}`,
//!
//! `f(θ) = A(θ) u(θ) + B(θ) u̇(θ) + E(θ)`, `A = ∂f/∂u`, `B = ∂f/∂u̇`, `E = f - A u - B u̇`,
//!
//! with `A`, `B`, `E` constant between *breaks*: the crossings `θ*` of its kinks and its time
//! jumps. The Galerkin harmonics `F_k = (1/π) ∫ f e^{-ikθ} dθ`, `k ≤ H`, need the Fourier
//! coefficients `A_m = (1/2π) ∫ A e^{-imθ} dθ` only for `|m| ≤ 2H`, and those are closed form
//! from the jumps `J_i` (right minus left) at the breaks `t_i`, with `A(θ_r)` at a point `θ_r`
//! inside a piece:
//!
//! `A_m = (1/2πim) Σ_i J_i (e^{-imt_i} - e^{-imθ_r})`, `A_0 = A(θ_r) + (1/2π) Σ_i J_i (θ_r + 2π - t̃_i)`
//!
//! (`t̃_i` the break moved into `(θ_r, θ_r + 2π]`). Sampled on `N >= 4H + 1` points, the
//! band-limited `A^T = Σ_{|m|≤2H} A_m e^{imθ}` times `u` has degree 3H and no aliasing in the
//! bins `0..=H`: the AFT of `A^T u + B^T u̇ + E^T` is the exact Galerkin projection, to
//! rounding, where the trapezoid rule on the law's own samples is off by O(h²) per kink
//! (O(h) where the force jumps) and the Euler–Maclaurin correction of the parent module by
//! the jumps of the third and higher derivatives it leaves out.
//!
//! The same coefficients are the exact Jacobian spectra: `∂F_k/∂U_l` holds `A_{k-l}` and
//! `i l Ω B_{k-l}`, plus, where the force jumps (contact damping), the moving crossing's
//! pulse `[f]/u'(θ*)` at `θ*` in `∂f/∂u` ([`super::correct_spectrum`] explains it).
//!
//! The interface of a law does not say that it is affine on its pieces. The AFT asks
//! `crate::force::affine` once per element, and [`PieceCoefficients::agrees_with`] checks
//! every sample of every evaluation against the law before the result is used.

use super::{derivatives, EdgeCrossing};
use crate::force::ForceLaw;
use num_complex::Complex64;
use std::f64::consts::{PI, TAU};

/// A break of the coefficients `(A, B, E)` along the orbit: its angle and the jumps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Break {
    /// The angle `t_i` in `[0, 2π)` (on the fundamental).
    pub theta: f64,
    /// `([A], [B], [E])`, right minus left.
    pub jumps: [f64; 3],
    /// `[f]/u'(θ*)` at a crossing (the weight of the moving jump in `∂f/∂u`), 0 at a time jump.
    pub pulse: f64,
}

/// The breaks of one element along its orbit and the coefficients at a point inside a piece.
#[derive(Debug, Clone, Default)]
pub struct PieceCoefficients {
    /// The breaks, sorted by angle.
    pub breaks: Vec<Break>,
    /// `θ_r` (in the middle of the widest gap between breaks) and `(A, B, E)` there.
    pub reference: (f64, [f64; 3]),
}

/// `(A, B, E)` of `law` at shaft angle `p`, coordinate `u` and rate `v`.
fn coefficients(law: &dyn ForceLaw, p: f64, u: f64, v: f64) -> [f64; 3] {
    let (a, b) = law.derivatives(p, u, v);
    [a, b, law.force(p, u, v) - a * u - b * v]
}

impl PieceCoefficients {
    /// Collects the breaks of `law` along the orbit with harmonics `uk`: the crossings
    /// `edges` and the time jumps `time_breaks` (angles on the fundamental), with `samples`
    /// samples, fundamental `Ω/ν` = `fundamental` and period multiple `nu`. `false` (and
    /// nothing usable) if a value is not finite or the jumps do not add up to zero over the
    /// period (a crossing missed, or a law that is not affine on its pieces).
    #[allow(clippy::too_many_arguments)]
    pub fn collect(
        &mut self,
        law: &dyn ForceLaw,
        edges: &[EdgeCrossing],
        time_breaks: &[f64],
        uk: &[Complex64],
        fundamental: f64,
        nu: usize,
        samples: usize,
    ) -> bool {
        let h = TAU / samples as f64;
        let shaft = |t: f64| (nu as f64 * t).rem_euclid(TAU);
        self.breaks.clear();
        for e in edges {
            let v = fundamental * e.slope;
            let delta = match 1e-6 * e.slope.abs() * h {
                x if x > 0.0 => x,
                _ => 1e-12 * (1.0 + e.kappa.abs()),
            };
            let p = shaft(e.theta);
            let above = coefficients(law, p, e.kappa + delta, v);
            let below = coefficients(law, p, e.kappa - delta, v);
            let s = if e.slope >= 0.0 { 1.0 } else { -1.0 };
            let jumps = [0, 1, 2].map(|i| s * (above[i] - below[i]));
            let jump_f = jumps[0] * e.kappa + jumps[1] * v + jumps[2];
            self.breaks.push(Break {
                theta: e.theta.rem_euclid(TAU),
                jumps,
                pulse: if e.slope != 0.0 {
                    jump_f / e.slope
                } else {
                    0.0
                },
            });
        }
        // A time jump: the same state, the shaft angle a little before and after.
        let dp = 1e-7 * h * nu as f64;
        for &t in time_breaks {
            let d = derivatives(uk, t);
            let (u, v, p) = (d[0], fundamental * d[1], shaft(t));
            let (before, after) = (
                coefficients(law, p - dp, u, v),
                coefficients(law, p + dp, u, v),
            );
            self.breaks.push(Break {
                theta: t.rem_euclid(TAU),
                jumps: [0, 1, 2].map(|i| after[i] - before[i]),
                pulse: 0.0,
            });
        }
        self.breaks
            .sort_unstable_by(|a, b| a.theta.total_cmp(&b.theta));
        if self.breaks.is_empty() {
            return false;
        }
        // The reference point in the middle of the widest gap between breaks (round the
        // circle): far from every break, so its side is no matter of rounding.
        let len = self.breaks.len();
        let (mut theta_r, mut widest) = (0.0, -1.0);
        for i in 0..len {
            let a = self.breaks[i].theta;
            let b = if i + 1 < len {
                self.breaks[i + 1].theta
            } else {
                self.breaks[0].theta + TAU
            };
            if b - a > widest {
                (theta_r, widest) = ((0.5 * (a + b)).rem_euclid(TAU), b - a);
            }
        }
        let d = derivatives(uk, theta_r);
        let value = coefficients(law, shaft(theta_r), d[0], fundamental * d[1]);
        self.reference = (theta_r, value);
        // The jumps of a periodic function add up to zero; each sum is compared with the
        // largest jump of its coefficient.
        let balanced = (0..3).all(|i| {
            let (sum, largest) = self.breaks.iter().fold((0.0, 0.0_f64), |(s, m), b| {
                (s + b.jumps[i], m.max(b.jumps[i].abs()))
            });
            sum.abs() <= 1e-9 * largest
        });
        let finite = value.iter().all(|v| v.is_finite())
            && self
                .breaks
                .iter()
                .all(|b| b.jumps.iter().all(|v| v.is_finite()) && b.pulse.is_finite());
        balanced && finite
    }

    /// `true` if `f_j = A u_j + B u̇_j + E` at every sample (`forces`, `u`, `du` at
    /// `θ_j = 2π j / N`) with the piecewise-constant coefficients, to 1e-9 of the terms'
    /// size plus 1e-12 of the largest force; samples within 1e-6 of a sample interval of a
    /// break are skipped (their side is a matter of rounding).
    pub fn agrees_with(&self, forces: &[f64], u: &[f64], du: &[f64]) -> bool {
        let n = forces.len();
        let h = TAU / n as f64;
        let largest = forces.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
        let (theta_r, mut c) = self.reference;
        // The coefficients just after θ = 0: undo the jumps at or before θ_r.
        for b in self.breaks.iter().filter(|b| b.theta <= theta_r) {
            for (ci, ji) in c.iter_mut().zip(&b.jumps) {
                *ci -= ji;
            }
        }
        let len = self.breaks.len();
        let distance = |i: usize, t: f64| {
            let d = (self.breaks[i % len].theta - t).abs();
            d.min(TAU - d)
        };
        let mut next = 0;
        for j in 0..n {
            let t = j as f64 * h;
            while next < len && self.breaks[next].theta <= t {
                for (ci, ji) in c.iter_mut().zip(&self.breaks[next].jumps) {
                    *ci += ji;
                }
                next += 1;
            }
            if len > 0 && distance(next + len - 1, t).min(distance(next, t)) <= 1e-6 * h {
                continue;
            }
            let (a, b, e) = (c[0] * u[j], c[1] * du[j], c[2]);
            let size = a.abs() + b.abs() + e.abs();
            if (forces[j] - (a + b + e)).abs() > 1e-9 * size + 1e-12 * largest {
                return false;
            }
        }
        true
    }

    /// The Fourier coefficients `A_m`, `B_m`, `E_m`, `m = 0..=max_order`, into the first
    /// `max_order + 1` entries of `out` (the rest set to zero) (module documentation).
    pub fn fourier_into(&self, max_order: usize, out: [&mut [Complex64]; 3]) {
        let (theta_r, value) = self.reference;
        let [a, b, e] = out;
        for o in [&mut *a, &mut *b, &mut *e] {
            o.fill(Complex64::default());
        }
        let top = max_order.min(a.len() - 1);
        let mut total = [0.0; 3];
        let mut mean = value;
        for br in self.breaks.iter().filter(|b| b.jumps != [0.0; 3]) {
            let moved = if br.theta > theta_r {
                br.theta
            } else {
                br.theta + TAU
            };
            for i in 0..3 {
                total[i] += br.jumps[i];
                mean[i] += br.jumps[i] * (theta_r + TAU - moved) / TAU;
            }
            // Σ_m J e^{-imt}: the power by recurrence, re-anchored every 64 orders.
            let step = Complex64::from_polar(1.0, -br.theta);
            let mut z = step;
            for m in 1..=top {
                if m % 64 == 0 {
                    z = Complex64::from_polar(1.0, -(m as f64) * br.theta);
                }
                a[m] += z * br.jumps[0];
                b[m] += z * br.jumps[1];
                e[m] += z * br.jumps[2];
                z *= step;
            }
        }
        let step = Complex64::from_polar(1.0, -theta_r);
        let mut z = step;
        for m in 1..=top {
            if m % 64 == 0 {
                z = Complex64::from_polar(1.0, -(m as f64) * theta_r);
            }
            // 1/(2π i m) = -i/(2π m).
            let scale = Complex64::new(0.0, -0.5 / (PI * m as f64));
            for (o, t) in [&mut *a, &mut *b, &mut *e].into_iter().zip(total) {
                o[m] = (o[m] - z * t) * scale;
            }
            z *= step;
        }
        for (o, m) in [a, b, e].into_iter().zip(mean) {
            o[0] = Complex64::new(m, 0.0);
        }
    }

    /// Adds the pulses of the moving force jumps, `[f]/u'(θ*) (1/2π) e^{-imθ*}`, to the
    /// spectrum `x` of `∂f/∂u` (all its entries).
    pub fn add_pulses(&self, x: &mut [Complex64]) {
        for br in self.breaks.iter().filter(|b| b.pulse != 0.0) {
            let step = Complex64::from_polar(1.0, -br.theta);
            let mut z = Complex64::new(0.5 * br.pulse / PI, 0.0);
            for xm in x.iter_mut() {
                *xm += z;
                z *= step;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An indicator of `(a, b)` with height 2 in `A` and -3 in `E`: the closed form
    /// `c_m = h (e^{-ima} - e^{-imb}) / (2π i m)`, `c_0 = h (b - a)/2π`, whatever the reference
    /// point; the samples agree with the pieces and disagree with a bent force.
    #[test]
    fn coefficients_of_an_indicator() {
        let (a, b) = (0.7, 4.1);
        let pieces = |theta_r: f64, inside: bool| PieceCoefficients {
            breaks: vec![
                Break {
                    theta: a,
                    jumps: [2.0, 0.0, -3.0],
                    pulse: 0.0,
                },
                Break {
                    theta: b,
                    jumps: [-2.0, 0.0, 3.0],
                    pulse: 0.0,
                },
            ],
            reference: (theta_r, if inside { [2.0, 0.0, -3.0] } else { [0.0; 3] }),
        };
        for p in [pieces(2.0, true), pieces(5.0, false), pieces(0.1, false)] {
            let mut out = [[Complex64::default(); 12]; 3];
            let [x, y, z] = &mut out;
            p.fourier_into(10, [x, y, z]);
            for (m, &got) in out[0].iter().enumerate().take(11) {
                let c = if m == 0 {
                    Complex64::new((b - a) / TAU, 0.0)
                } else {
                    let mf = m as f64;
                    (Complex64::from_polar(1.0, -mf * a) - Complex64::from_polar(1.0, -mf * b))
                        / Complex64::new(0.0, TAU * mf)
                };
                assert!((got - 2.0 * c).norm() < 1e-15, "m {m}: {got}");
                assert!((out[2][m] + 3.0 * c).norm() < 1e-15);
                assert_eq!(out[1][m], Complex64::default());
            }
            assert_eq!(out[0][11], Complex64::default());
            let n = 64;
            let u: Vec<f64> = (0..n).map(|j| (j as f64).sin()).collect();
            let theta = |j: usize| TAU * j as f64 / n as f64;
            let inside = |j: usize| theta(j) > a && theta(j) < b;
            let f: Vec<f64> = (0..n)
                .map(|j| if inside(j) { 2.0 * u[j] - 3.0 } else { 0.0 })
                .collect();
            assert!(p.agrees_with(&f, &u, &vec![0.0; n]));
            let bent: Vec<f64> = f.iter().zip(&u).map(|(f, u)| f + 1e-6 * u * u).collect();
            assert!(!p.agrees_with(&bent, &u, &vec![0.0; n]));
        }
    }
}
