//! Floquet multipliers of a linear time-invariant model in closed form.
//!
//! Where every element is linear and time-invariant ([`Model::is_linear_time_invariant`]), the
//! variational equation does not depend on the orbit: `ż = A z` with the constant
//!
//! `A = [[0, I], [-M⁻¹ K0, -M⁻¹ D0]]`,
//!
//! so the monodromy matrix is `Φ(T) = e^{A T}` and the multipliers are `μ_j = e^{λ_j T}` for
//! the eigenvalues `λ_j` of `A`, `T = 2π ν / Ω` the orbit's period. The eigenvalues do not
//! depend on the speed: a sweep computes them once ([`FloquetCache`](crate::stability::FloquetCache)) and each point costs
//! `2n` exponentials. The HB solution of such a model is the exact periodic orbit (loads at
//! orders up to H, nothing couples the harmonics), so nothing is shot or polished.
//!
//! A rigid-body mode has the double eigenvalue 0 (multiplier 1 by construction): the `2r`
//! eigenvalues closest to 0 are left out ([`Floquet::neutral`]), `r` the rigid-body modes found
//! as for the other methods ([`super::neutral`]).

use super::neutral::rigid_body_modes;
use super::system::Coordinates;
use super::{Floquet, Orbit};
use crate::error::Result;
use crate::model::Model;
use crate::solution::Solution;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The eigenvalues of `A` that decide stability and the number of neutral multipliers left
/// out, kept by a sweep ([`FloquetCache`](crate::stability::FloquetCache)).
#[derive(Debug, Clone)]
pub(crate) struct StateEigenvalues {
    lambdas: Vec<Complex64>,
    neutral: usize,
    /// The model they belong to ([`fingerprint`]): a parameter sweep's points are different
    /// models sharing one cache.
    model: u64,
}

/// A hash of `M`, `K0` and `D0` (their sparse entries).
fn fingerprint(model: &Model) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for a in [model.mass().clone(), model.k0(), model.d0()] {
        for (i, j, v) in a.iter() {
            (i, j, v.to_bits()).hash(&mut h);
        }
        u64::MAX.hash(&mut h);
    }
    h.finish()
}

/// The multipliers of `solution` of the linear time-invariant `model` (`None` where the closed
/// form does not apply: a model with a time-varying or nonlinear element, a singular mass
/// matrix, or too many DOFs for the dense `2n × 2n` eigenvalue problem).
pub(crate) fn floquet(
    model: &Model,
    solution: &Solution,
    kept: &mut Option<StateEigenvalues>,
) -> Result<Option<Floquet>> {
    if !model.is_linear_time_invariant() || model.n_dofs() > MAX_DOFS {
        return Ok(None);
    }
    let id = fingerprint(model);
    if kept.as_ref().is_none_or(|e| e.model != id) {
        *kept = state_eigenvalues(model, id)?;
    }
    let Some(eig) = &*kept else {
        return Ok(None);
    };
    let basis = solution.basis();
    let period = std::f64::consts::TAU * basis.subharmonic() as f64 / basis.omega();
    let mut multipliers: Vec<Complex64> = eig.lambdas.iter().map(|l| (l * period).exp()).collect();
    multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    Ok(Some(Floquet {
        multipliers,
        neutral: eig.neutral,
        orbit_correction: 0.0,
        polished: true,
        orbit_start: super::hb_state::hb_start(solution),
        steps: 0,
        reduction: None,
        orbit: Orbit::Exact,
        orbit_difference: None,
        orbit_distance: 0.0,
        other_orbit: None,
    }))
}

/// The eigenvalues `λ` of the state matrix of the linear time-invariant `model` (rigid-body
/// modes left out): where its resonances lie (`None` where not available).
pub(crate) fn eigenvalues(model: &Model) -> Result<Option<Vec<Complex64>>> {
    if !model.is_linear_time_invariant() || model.n_dofs() > MAX_DOFS {
        return Ok(None);
    }
    Ok(state_eigenvalues(model, 0)?.map(|e| e.lambdas))
}

/// Largest model whose state matrix is decomposed densely (`2n × 2n`: 20 s at 900 DOFs, still
/// less than the shooting it replaces).
const MAX_DOFS: usize = 1000;

/// The eigenvalues of `A` without the zeros of the rigid-body modes (two per free mode, one per
/// mode held only by damping); `None` if `M` is not
/// positive definite.
fn state_eigenvalues(model: &Model, id: u64) -> Result<Option<StateEigenvalues>> {
    let n = model.n_dofs();
    let dense = model.dense("stability of a linear time-invariant model")?;
    let Some(chol) = dense.mass.clone().cholesky() else {
        return Ok(None);
    };
    let (mk, md) = (chol.solve(&dense.k0), chol.solve(&dense.d0));
    let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        for j in 0..n {
            a[(n + i, j)] = -mk[(i, j)];
            a[(n + i, n + j)] = -md[(i, j)];
        }
    }
    let mut lambdas: Vec<Complex64> = a.complex_eigenvalues().iter().copied().collect();
    if lambdas
        .iter()
        .any(|l| !(l.re.is_finite() && l.im.is_finite()))
    {
        return Ok(None);
    }
    let neutral = rigid_body_modes(&Coordinates::full(model)).multipliers();
    lambdas.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    lambdas.drain(..neutral.min(lambdas.len()));
    Ok(Some(StateEigenvalues {
        lambdas,
        neutral,
        model: id,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{HarmonicBalance, HarmonicBasis, Newton};

    /// A damped oscillator `m ẍ + c ẋ + k x = cos Ωt`: `λ = -ζω ± iω√(1-ζ²)`, so both
    /// multipliers have the modulus `e^{-ζω T}`; against the Runge–Kutta monodromy too.
    #[test]
    fn an_oscillator_has_the_closed_form_multipliers() {
        let (m, c, k, w) = (2.0, 0.3, 50.0, 3.0);
        let model = Model::builder(&["x"])
            .mass_diagonal(&[m])
            .damping(DMatrix::from_element(1, 1, c))
            .stiffness(DMatrix::from_element(1, 1, k))
            .load("x", 1, 1.0, 0.0)
            .build()
            .unwrap();
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(w, 3).unwrap()).unwrap();
        let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
        let f = floquet(&model, &sol, &mut None).unwrap().unwrap();
        let t = std::f64::consts::TAU / w;
        let decay = (-c / (2.0 * m) * t).exp();
        assert_eq!(f.multipliers.len(), 2);
        for mu in &f.multipliers {
            assert!((mu.norm() - decay).abs() < 1e-14 * decay, "{mu} vs {decay}");
        }
        let wd = (k / m - (c / (2.0 * m)).powi(2)).sqrt();
        let arg = (wd * t).rem_euclid(std::f64::consts::TAU);
        let got = f.multipliers[0].arg().abs();
        let want = if arg > std::f64::consts::PI {
            std::f64::consts::TAU - arg
        } else {
            arg
        };
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}
