//! The HB orbit as the path of the Runge–Kutta flow: the variational equation along the HB
//! solution itself, for laws that are not affine between their kinks (a cosine or Fourier
//! mesh stiffness under backlash, smooth nonlinear springs), where the exponential flow's
//! pieces ([`harmonic_orbit`](crate::stability::harmonic_orbit)) do not apply.
//!
//! With `q_H(t) = Re Σ_{k=0}^{H} Q_k e^{ikθ}`, `θ = ω t` (`ω` the fundamental `Ω/ν`), the flow
//! integrates `q̇ = v`, `v̇ = a_H(t)` with `a_H(t) = Re Σ_{k≥1} −(kω)² Q_k e^{ikθ}` from the HB
//! state at `t = 0` instead of the equations of motion, so its state follows the HB orbit to
//! the integrator's tolerance and returns to its start after `ν` forcing periods whatever
//! the HB solution's residual; `Φ̃' = Ã(t) Φ̃` is integrated along it with every kink crossing
//! located and its saltation matrix applied, as along an integrated orbit
//! ([`flow`](super::flow)). The multipliers are those of the linearisation about the HB
//! solution (Hill's method's), accurate to about its own error: what a strongly unstable
//! orbit needs, whose unstable direction single shooting cannot hold
//! ([`orbit_identity`](crate::stability::choice::orbit_identity)).

use num_complex::Complex64;

/// The acceleration of the HB orbit in the flow's coordinates.
#[derive(Debug, Clone)]
pub(crate) struct Guide {
    /// `−(kω)² Q_k` for `k = 1..=H`, harmonic-major (`n` per harmonic).
    acceleration: Vec<Complex64>,
    /// The fundamental `ω = Ω/ν` in rad/s.
    fundamental: f64,
    n: usize,
    /// The time of the flow's `t = 0` on the orbit: each forcing period restarts the flow's
    /// clock, while the orbit of a period-`ν` solution goes on (`p · 2π/Ω` in period `p`).
    pub(crate) offset: f64,
}

impl Guide {
    /// The guide of the orbit with harmonics `harmonics` (`Q_k`, harmonic-major, `k = 0..=H`,
    /// `n` coordinates each) and fundamental `fundamental`.
    pub(crate) fn new(harmonics: &[Complex64], n: usize, fundamental: f64) -> Self {
        let acceleration = harmonics
            .chunks(n)
            .enumerate()
            .skip(1)
            .flat_map(|(k, q)| {
                let s = -(k as f64 * fundamental).powi(2);
                q.iter().map(move |z| z * s)
            })
            .collect();
        Self {
            acceleration,
            fundamental,
            n,
            offset: 0.0,
        }
    }

    /// `out ← a_H(t)`: the powers `e^{ikθ}` by recurrence from `e^{iθ}` (rounding grows like
    /// `k ε`, 1e-14 at H = 128).
    pub(crate) fn acceleration_into(&self, t: f64, out: &mut [f64]) {
        out.fill(0.0);
        let (s, c) = (self.fundamental * (t + self.offset)).sin_cos();
        let step = Complex64::new(c, s);
        let mut turn = step;
        for a in self.acceleration.chunks(self.n) {
            for (o, z) in out.iter_mut().zip(a) {
                *o += z.re * turn.re - z.im * turn.im;
            }
            turn *= step;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `q = 0.3 cos θ − 0.2 sin 2θ + 0.1` (Q_1 = 0.3, Q_2 = 0.2i): `q̈ = −0.3 ω² cos θ + 0.8 ω² sin 2θ`.
    #[test]
    fn acceleration_is_the_second_derivative_of_the_orbit() {
        let w = 1.7;
        let q = [
            Complex64::new(0.1, 0.0),
            Complex64::new(0.3, 0.0),
            Complex64::new(0.0, 0.2),
        ];
        let guide = Guide::new(&q, 1, w);
        for t in [0.0, 0.4, 2.9, 11.3] {
            let mut a = [0.0];
            guide.acceleration_into(t, &mut a);
            let th = w * t;
            let expect = -0.3 * w * w * th.cos() + 0.8 * w * w * (2.0 * th).sin();
            assert!(
                (a[0] - expect).abs() < 1e-13,
                "{t}: {} against {expect}",
                a[0]
            );
        }
    }
}
