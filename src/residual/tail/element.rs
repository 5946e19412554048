//! A jumping element of the tail correction: its coefficients `k(θ)`, `d(θ)` tabulated on the
//! fine grid, and the force harmonics of a coordinate given by its harmonics.
//!
//! Only the varying parts of the coefficients couple harmonics: a constant `k̄ u + d̄ u̇`
//! maps harmonic `l` onto itself. Where the damping varies with the stiffness,
//! `d(θ) = d̄ + β (k(θ) − k̄)` (a mesh with `d = β k`), the coupling part of the force is
//! `k(θ) y` with `y = u + β u̇`, whose harmonics are `(1 + i lΩβ) u_l`: one synthesis and
//! one analysis per product instead of two and one, and a product with a table instead of a
//! call of the law.

use crate::force::ForceLaw;
use crate::harmonic::{AftPlan, AftScratch};
use num_complex::Complex64;

/// How the damping of a jumping element varies in time.
#[derive(Debug)]
enum Damping {
    /// `d(θ) = d̄ + β (k(θ) − k̄)`: the coupling part of the force is `k(θ) (u + β u̇)`.
    Proportional(f64),
    /// `d(θ)` on its own, at the fine grid's angles.
    Varying(Vec<f64>),
}

/// A jumping element: its index among the active elements and its band-limited coefficients
/// at the fine grid's angles.
#[derive(Debug)]
pub(super) struct TailElement {
    pub(super) active: usize,
    stiffness: Vec<f64>,
    damping: Damping,
}

impl TailElement {
    /// Tabulates the coefficients of `law` (linear in the state: `f = k(θ) u + d(θ) u̇`, so
    /// its derivatives at rest are `k`, `d`) at `thetas`.
    pub(super) fn new(active: usize, law: &dyn ForceLaw, thetas: &[f64]) -> Self {
        let n = thetas.len();
        let rest = vec![0.0; n];
        let (mut k, mut d) = (vec![0.0; n], vec![0.0; n]);
        law.derivatives_batch(thetas, &rest, &rest, &mut k, &mut d);
        let damping = match proportionality(&k, &d) {
            Some(beta) => Damping::Proportional(beta),
            None => Damping::Varying(d),
        };
        Self {
            active,
            stiffness: k,
            damping,
        }
    }

    /// The FFTs one [`TailElement::force_harmonics`] takes.
    pub(super) fn ffts(&self) -> usize {
        match self.damping {
            Damping::Proportional(_) => 2,
            Damping::Varying(_) => 3,
        }
    }

    /// The harmonics `0..=L` of the force `k(θ) u + d(θ) u̇` of the coordinate with harmonics
    /// `uk` (`0..=L`) at the fundamental `omega`, into `out`; `u`, `du` are sample buffers.
    /// On the harmonics `uk` has, a constant-coefficient term (`(d̄ − β k̄) u̇`) may be left
    /// out: the correction reads only harmonics that `uk` does not have.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn force_harmonics(
        &self,
        plan: &AftPlan,
        omega: f64,
        uk: &[Complex64],
        u: &mut [f64],
        du: &mut [f64],
        out: &mut [Complex64],
        aft: &mut AftScratch,
    ) {
        match &self.damping {
            Damping::Proportional(beta) => {
                let beta = *beta;
                plan.synthesize_into(uk, |l| Complex64::new(1.0, l as f64 * omega * beta), u, aft);
                for (y, k) in u.iter_mut().zip(&self.stiffness) {
                    *y *= k;
                }
            }
            Damping::Varying(d) => {
                plan.synthesize_into(uk, |_| Complex64::new(1.0, 0.0), u, aft);
                plan.synthesize_into(uk, |l| Complex64::new(0.0, l as f64 * omega), du, aft);
                for ((x, v), (k, d)) in u
                    .iter_mut()
                    .zip(du.iter())
                    .zip(self.stiffness.iter().zip(d))
                {
                    *x = k * *x + d * v;
                }
            }
        }
        plan.analyze_into(u, out, aft);
    }
}

/// `β` where `d = d̄ + β (k − k̄)` at every sample to rounding (least squares, then a check of
/// every sample against 1e-12 of the largest damping); `None` where the damping varies on its
/// own.
fn proportionality(k: &[f64], d: &[f64]) -> Option<f64> {
    let n = k.len() as f64;
    let (km, dm) = (k.iter().sum::<f64>() / n, d.iter().sum::<f64>() / n);
    let (mut kk, mut kd) = (0.0, 0.0);
    for (k, d) in k.iter().zip(d) {
        kk += (k - km) * (k - km);
        kd += (k - km) * (d - dm);
    }
    let beta = if kk > 0.0 { kd / kk } else { 0.0 };
    let scale = d.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
    let fits = k
        .iter()
        .zip(d)
        .all(|(k, d)| (d - dm - beta * (k - km)).abs() <= 1e-12 * scale);
    (beta.is_finite() && fits).then_some(beta)
}

#[cfg(test)]
mod tests {
    use super::{proportionality, Damping, TailElement};
    use crate::harmonic::{AftPlan, HarmonicBasis};
    use num_complex::Complex64;

    #[test]
    fn damping_proportional_to_stiffness_is_recognised() {
        let k = [1.0, 2.0, 2.0, 1.0];
        let d: Vec<f64> = k.iter().map(|k| 0.5 + 1e-3 * k).collect();
        assert!((proportionality(&k, &d).unwrap() - 1e-3).abs() < 1e-15);
        // No damping: β = 0; damping varying on its own: none.
        assert_eq!(proportionality(&k, &[0.0; 4]), Some(0.0));
        assert_eq!(proportionality(&k, &[0.0, 1.0, 0.0, 1.0]), None);
        // A constant stiffness with a varying damping.
        assert_eq!(proportionality(&[1.0; 4], &[0.0, 1.0, 0.0, 1.0]), None);
    }

    /// The coupling force of `y = u + β u̇` (two FFTs) against `k u + d u̇` sample by sample
    /// (three), and against the convolution of the coefficients' harmonics with `u`'s.
    #[test]
    fn proportional_and_sampled_damping_give_the_same_force() {
        let (top, samples, omega, beta) = (20, 64, 3.0, 0.05);
        let plan = AftPlan::new(
            HarmonicBasis::new(omega, top)
                .unwrap()
                .with_samples(samples)
                .unwrap(),
        );
        let mut aft = plan.make_scratch();
        let thetas: Vec<f64> = (0..samples)
            .map(|j| std::f64::consts::TAU * j as f64 / samples as f64)
            .collect();
        // k(θ) = 2 + cos 3θ, d = 0.1 + β k: harmonics up to 3, products alias-free.
        let k: Vec<f64> = thetas.iter().map(|t| 2.0 + (3.0 * t).cos()).collect();
        let d: Vec<f64> = k.iter().map(|k| 0.1 + beta * k).collect();
        let proportional = TailElement {
            active: 0,
            stiffness: k.clone(),
            damping: Damping::Proportional(beta),
        };
        let varying = TailElement {
            active: 0,
            stiffness: k,
            damping: Damping::Varying(d),
        };
        let mut uk = vec![Complex64::default(); top + 1];
        uk[0] = Complex64::new(0.7, 0.0);
        uk[5] = Complex64::new(0.3, -1.1);
        uk[8] = Complex64::new(-0.4, 0.2);
        let (mut u, mut du) = (vec![0.0; samples], vec![0.0; samples]);
        let (mut a, mut b) = (
            vec![Complex64::default(); top + 1],
            vec![Complex64::default(); top + 1],
        );
        proportional.force_harmonics(&plan, omega, &uk, &mut u, &mut du, &mut a, &mut aft);
        varying.force_harmonics(&plan, omega, &uk, &mut u, &mut du, &mut b, &mut aft);
        // The harmonics 3 away from those of u: (k u)_l = κ_{±3} u_{l∓3}, κ_{±3} = 1/2; the
        // constant d̄ − β k̄ = 0.1 adds only on u's own harmonics.
        for l in [2, 11] {
            let j = if l == 2 { 5 } else { 8 };
            let y = uk[j] * Complex64::new(1.0, j as f64 * omega * beta);
            assert!(
                (a[l] - 0.5 * y).norm() < 1e-14,
                "{l}: {} vs {}",
                a[l],
                0.5 * y
            );
        }
        for l in 1..=top {
            if ![0, 5, 8].contains(&l) {
                assert!((a[l] - b[l]).norm() < 1e-14, "{l}: {} vs {}", a[l], b[l]);
            }
        }
        assert_eq!((proportional.ffts(), varying.ffts()), (2, 3));
    }
}
