//! The state scales of the time integration's tolerances.

use crate::model::Model;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// State scales `(q, q̇)`: `s_q` from the linear frequency-domain response to the loads (with
/// the elements' linear parts), `s_q̇ = s_q max(k Ω, ω_max)` with the highest undamped natural
/// frequency `ω_max` of `(M, K0)`, since time-varying and nonlinear forces ring the structure at
/// its natural frequencies. 1 where that is zero or singular.
pub(super) fn state_scale(model: &Model, omega: f64) -> Vec<f64> {
    let n = model.n_dofs();
    let Ok(dense) = model.dense("time integration") else {
        return vec![1.0; 2 * n];
    };
    let (m, d0, k0) = (&dense.mass, &dense.d0, &dense.k0);
    let mut q = vec![0.0; n];
    let mut w_max: f64 = 0.0;
    let orders: std::collections::BTreeSet<usize> = model.loads().iter().map(|l| l.order).collect();
    for k in orders {
        let w = k as f64 * omega;
        w_max = w_max.max(w);
        let z = DMatrix::from_fn(n, n, |i, j| {
            Complex64::new(k0[(i, j)] - w * w * m[(i, j)], w * d0[(i, j)])
        });
        let mut f = DVector::from_element(n, Complex64::default());
        for l in model.loads().iter().filter(|l| l.order == k) {
            let (c, s) = l.at(omega);
            f[l.dof] += crate::harmonic::from_cos_sin(c, s);
        }
        if let Some(x) = z.lu().solve(&f) {
            for i in 0..n {
                if x[i].norm().is_finite() {
                    q[i] += x[i].norm();
                }
            }
        }
    }
    if let Some(chol) = m.clone().cholesky() {
        // ω² are the eigenvalues of L⁻¹ K0 L⁻ᵀ (symmetric part), M = L Lᵀ.
        let l_inv = chol
            .l()
            .try_inverse()
            .unwrap_or_else(|| DMatrix::identity(n, n));
        let a = &l_inv * k0 * l_inv.transpose();
        let a = (&a + a.transpose()) * 0.5;
        let lambda = a.symmetric_eigenvalues().max();
        if lambda.is_finite() && lambda > 0.0 {
            w_max = w_max.max(lambda.sqrt());
        }
    }
    let qmax = q.iter().cloned().fold(0.0, f64::max);
    let qs = if qmax > 0.0 && qmax.is_finite() {
        qmax
    } else {
        1.0
    };
    let vs = qs * if w_max > 0.0 { w_max } else { omega };
    let mut s = vec![qs; n];
    s.extend(std::iter::repeat_n(vs, n));
    s
}
