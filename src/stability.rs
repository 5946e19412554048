//! Stability of a periodic solution: Floquet multipliers from the monodromy matrix.
//!
//! The variational equation of `M q̈ + D q̇ + K q + Σ w f(θ, w·q, w·q̇) = f(t)` about the periodic
//! solution `q*(t)` is `ż = A(t) z`, `z = (δq, δq̇)`, with
//!
//! `A(t) = [[0, I], [-M⁻¹ (K + Σ w k(t) wᵀ), -M⁻¹ (D + Σ w d(t) wᵀ)]]`,
//! `k(t) = ∂f/∂u`, `d(t) = ∂f/∂u̇` at `(Ω t, w·q*, w·q̇*)`.
//!
//! The monodromy matrix `Φ(T)` comes from integrating `Φ̇ = A(t) Φ`, `Φ(0) = I`, over one period
//! with the classical Runge–Kutta method on `steps` equal steps (A at the step ends and
//! midpoints, from the harmonic solution). Its eigenvalues are the Floquet multipliers: the
//! solution is stable if all lie inside the unit circle. A multiplier leaving through +1 is a
//! fold (or symmetry-breaking), through −1 a period doubling, a complex pair a Neimark–Sacker
//! bifurcation.

use crate::error::{Error, Result};
use crate::model::Model;
use crate::solution::Solution;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// How a multiplier sits relative to the unit circle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bifurcation {
    /// Real multiplier near +1.
    Fold,
    /// Real multiplier near −1.
    PeriodDoubling,
    /// Complex pair on the unit circle.
    NeimarkSacker,
}

/// Floquet multipliers of a periodic solution.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Floquet {
    /// The multipliers, largest modulus first.
    pub multipliers: Vec<Complex64>,
}

impl Floquet {
    /// Largest modulus.
    pub fn max_abs(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |m| m.norm())
    }

    /// `true` if every multiplier lies inside the unit circle (with margin `1e-6`).
    pub fn is_stable(&self) -> bool {
        self.max_abs() < 1.0 - 1e-6
    }

    /// The kind of the critical multiplier (the one of largest modulus), by where it sits on
    /// the unit circle: argument within 0.1 rad of 0 (fold), of π (period doubling), else
    /// Neimark–Sacker. (A real pair near +1 can come out of the eigensolver as a complex pair
    /// with a tiny argument, hence the margin.)
    pub fn critical(&self) -> Option<Bifurcation> {
        let m = *self.multipliers.first()?;
        let angle = m.arg().abs();
        Some(if angle < 0.1 {
            Bifurcation::Fold
        } else if angle > std::f64::consts::PI - 0.1 {
            Bifurcation::PeriodDoubling
        } else {
            Bifurcation::NeimarkSacker
        })
    }
}

/// Floquet multipliers of `solution` (a periodic solution of `model`) with `steps` Runge–Kutta
/// steps per period (≥ 16; 4N is a good choice for non-smooth contact).
pub fn floquet(model: &Model, solution: &Solution, steps: usize) -> Result<Floquet> {
    if steps < 16 {
        return Err(Error::invalid("floquet", "steps", steps as f64, ">= 16"));
    }
    let n = model.n_dofs();
    let omega = solution.basis().omega();
    let period = std::f64::consts::TAU / omega;
    let dt = period / steps as f64;
    let chol = model
        .mass()
        .clone()
        .cholesky()
        .ok_or_else(|| Error::MassNotPositiveDefinite {
            reason: "Cholesky factorisation failed".into(),
        })?;
    let m_inv = chol.inverse();
    // A(t) at 2·steps + 1 equidistant times (ends and midpoints), written into `a`.
    let h = solution.basis().harmonics();
    let harmonics = solution.harmonics();
    let (ks, ds) = (model.structural_stiffness(), model.structural_damping());
    let mut q = vec![0.0; n];
    let mut v = vec![0.0; n];
    let mut k = DMatrix::zeros(n, n);
    let mut d = DMatrix::zeros(n, n);
    let mut mk = DMatrix::zeros(n, n);
    let mut md = DMatrix::zeros(n, n);
    let mut a_at = |j: usize, a: &mut DMatrix<f64>| {
        let theta = omega * j as f64 * 0.5 * dt;
        // q, q̇ by the recurrence e^{ikθ} = e^{iθ} e^{i(k-1)θ}: one sin/cos per time.
        let step = Complex64::from_polar(1.0, theta);
        let mut rot = Complex64::new(1.0, 0.0);
        for i in 0..n {
            q[i] = harmonics[i].re;
            v[i] = 0.0;
        }
        for kk in 1..=h {
            rot *= step;
            let kw = kk as f64 * omega;
            for i in 0..n {
                let z = harmonics[kk * n + i] * rot;
                q[i] += z.re;
                v[i] -= kw * z.im;
            }
        }
        k.copy_from(ks);
        d.copy_from(ds);
        for e in model.elements() {
            let (dk, dd) = e.law().derivatives(theta, e.gather(&q), e.gather(&v));
            for &(i, wi) in e.weights() {
                for &(jj, wj) in e.weights() {
                    k[(i, jj)] += dk * wi * wj;
                    d[(i, jj)] += dd * wi * wj;
                }
            }
        }
        m_inv.mul_to(&k, &mut mk);
        m_inv.mul_to(&d, &mut md);
        a.fill(0.0);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for jj in 0..n {
                a[(n + i, jj)] = -mk[(i, jj)];
                a[(n + i, n + jj)] = -md[(i, jj)];
            }
        }
    };
    let s2 = 2 * n;
    let mut phi = DMatrix::<f64>::identity(s2, s2);
    let (mut a0, mut am, mut a1) = (
        DMatrix::zeros(s2, s2),
        DMatrix::zeros(s2, s2),
        DMatrix::zeros(s2, s2),
    );
    let (mut k1, mut k2, mut k3, mut k4) = (
        DMatrix::zeros(s2, s2),
        DMatrix::zeros(s2, s2),
        DMatrix::zeros(s2, s2),
        DMatrix::zeros(s2, s2),
    );
    let mut tmp = DMatrix::zeros(s2, s2);
    a_at(0, &mut a0);
    for st in 0..steps {
        a_at(2 * st + 1, &mut am);
        a_at(2 * st + 2, &mut a1);
        a0.mul_to(&phi, &mut k1);
        tmp.copy_from(&phi);
        axpy(&mut tmp, 0.5 * dt, &k1);
        am.mul_to(&tmp, &mut k2);
        tmp.copy_from(&phi);
        axpy(&mut tmp, 0.5 * dt, &k2);
        am.mul_to(&tmp, &mut k3);
        tmp.copy_from(&phi);
        axpy(&mut tmp, dt, &k3);
        a1.mul_to(&tmp, &mut k4);
        axpy(&mut phi, dt / 6.0, &k1);
        axpy(&mut phi, dt / 3.0, &k2);
        axpy(&mut phi, dt / 3.0, &k3);
        axpy(&mut phi, dt / 6.0, &k4);
        std::mem::swap(&mut a0, &mut a1);
    }
    if !phi.iter().all(|v| v.is_finite()) {
        return Err(Error::NonFinite {
            what: "monodromy matrix".into(),
        });
    }
    let mut multipliers: Vec<Complex64> = phi.complex_eigenvalues().iter().copied().collect();
    multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    Ok(Floquet { multipliers })
}

/// `y += a x` for matrices of one shape.
fn axpy(y: &mut DMatrix<f64>, a: f64, x: &DMatrix<f64>) {
    for (yi, xi) in y.iter_mut().zip(x.iter()) {
        *yi += a * xi;
    }
}
