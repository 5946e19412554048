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

    /// The kind of the critical multiplier (the one of largest modulus).
    pub fn critical(&self) -> Option<Bifurcation> {
        let m = *self.multipliers.first()?;
        Some(if m.im.abs() > 1e-6 * m.norm().max(1.0) {
            Bifurcation::NeimarkSacker
        } else if m.re > 0.0 {
            Bifurcation::Fold
        } else {
            Bifurcation::PeriodDoubling
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
    // A(t) at 2·steps + 1 equidistant times (ends and midpoints).
    let a_at = |j: usize| -> DMatrix<f64> {
        let t = j as f64 * 0.5 * dt;
        let theta = omega * t;
        let q: Vec<f64> = (0..n).map(|i| solution.displacement(i, theta)).collect();
        let v: Vec<f64> = (0..n).map(|i| solution.velocity(i, theta)).collect();
        let mut k = model.structural_stiffness().clone();
        let mut d = model.structural_damping().clone();
        for e in model.elements() {
            let (dk, dd) = e.law().derivatives(theta, e.gather(&q), e.gather(&v));
            for &(i, wi) in e.weights() {
                for &(jj, wj) in e.weights() {
                    k[(i, jj)] += dk * wi * wj;
                    d[(i, jj)] += dd * wi * wj;
                }
            }
        }
        let mk = -(&m_inv * k);
        let md = -(&m_inv * d);
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for jj in 0..n {
                a[(n + i, jj)] = mk[(i, jj)];
                a[(n + i, n + jj)] = md[(i, jj)];
            }
        }
        a
    };
    let mut phi = DMatrix::<f64>::identity(2 * n, 2 * n);
    let mut a0 = a_at(0);
    for s in 0..steps {
        let am = a_at(2 * s + 1);
        let a1 = a_at(2 * s + 2);
        let k1 = &a0 * &phi;
        let k2 = &am * (&phi + &k1 * (0.5 * dt));
        let k3 = &am * (&phi + &k2 * (0.5 * dt));
        let k4 = &a1 * (&phi + &k3 * dt);
        phi += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
        a0 = a1;
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
