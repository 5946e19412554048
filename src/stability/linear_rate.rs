//! The constant linear part of a variational equation's acceleration in one pass:
//! `a = −M⁻¹ (K0 q + D0 q̇)` for a diagonal `M`.
//!
//! `K0` and `D0` are merged and scaled by `−1/M_ii` once. The diagonals `j − i = d` that hold
//! an entry in at least half the rows (a shaft line's or chain's band) are kept as dense
//! vectors, `a_i += s_{i,d} q_{i+d} + c_{i,d} q̇_{i+d}`: contiguous loops the compiler turns
//! into vector instructions. The few other entries (branches, meshes across the line) are
//! kept in compressed rows. This product is nearly all the cost of the monodromy action of
//! [`sparse_action`](super::large::sparse_action) (four per Runge–Kutta step); the band form made the
//! 1000-DOF chain's action three times faster than compressed rows alone.

use crate::model::{Model, SparseMatrix};
use std::collections::BTreeMap;

/// `−M⁻¹ K0` and `−M⁻¹ D0`: dense diagonals and compressed rows for the rest.
pub(crate) struct LinearRate {
    /// `(d, −K0_{i,i+d} / M_ii, −D0_{i,i+d} / M_ii)` for every row `i` (zero where `i + d` is
    /// outside or the entry is absent).
    diagonals: Vec<(isize, Vec<f64>, Vec<f64>)>,
    row_ptr: Vec<usize>,
    columns: Vec<usize>,
    /// `(−K0_ij / M_ii, −D0_ij / M_ii)` per stored position off the dense diagonals.
    entries: Vec<(f64, f64)>,
}

impl LinearRate {
    /// `k0` and `d0` merged and scaled by `−inv_mass` (`1 / M_ii`) per row.
    pub(crate) fn new(k0: &SparseMatrix, d0: &SparseMatrix, inv_mass: &[f64]) -> Self {
        let n = inv_mass.len();
        let mut merged: BTreeMap<(usize, usize), (f64, f64)> = BTreeMap::new();
        for (i, j, v) in k0.iter() {
            merged.entry((i, j)).or_default().0 -= v * inv_mass[i];
        }
        for (i, j, v) in d0.iter() {
            merged.entry((i, j)).or_default().1 -= v * inv_mass[i];
        }
        let mut counts: BTreeMap<isize, usize> = BTreeMap::new();
        for &(i, j) in merged.keys() {
            *counts.entry(j as isize - i as isize).or_default() += 1;
        }
        let mut diagonals: Vec<(isize, Vec<f64>, Vec<f64>)> = counts
            .into_iter()
            .filter(|&(_, c)| 2 * c >= n)
            .map(|(d, _)| (d, vec![0.0; n], vec![0.0; n]))
            .collect();
        let (mut row_ptr, mut columns, mut entries) = (vec![0; n + 1], Vec::new(), Vec::new());
        for (&(i, j), &(k, c)) in &merged {
            let d = j as isize - i as isize;
            match diagonals.iter_mut().find(|(e, _, _)| *e == d) {
                Some((_, s, a)) => (s[i], a[i]) = (k, c),
                None => {
                    columns.push(j);
                    entries.push((k, c));
                    row_ptr[i + 1] += 1;
                }
            }
        }
        for i in 0..n {
            row_ptr[i + 1] += row_ptr[i];
        }
        Self {
            diagonals,
            row_ptr,
            columns,
            entries,
        }
    }

    /// `out = −M⁻¹ (K0 q + D0 v)`.
    pub(crate) fn apply(&self, q: &[f64], v: &[f64], out: &mut [f64]) {
        let n = out.len();
        out.fill(0.0);
        for (d, s, c) in &self.diagonals {
            // Rows i with 0 ≤ i + d < n.
            let (lo, hi) = (
                (-d).max(0) as usize,
                (n as isize - d).min(n as isize) as usize,
            );
            let shifted = (lo as isize + d) as usize;
            let (q, v) = (&q[shifted..], &v[shifted..]);
            for ((((o, s), c), q), v) in out[lo..hi]
                .iter_mut()
                .zip(&s[lo..hi])
                .zip(&c[lo..hi])
                .zip(q)
                .zip(v)
            {
                *o += s * q + c * v;
            }
        }
        for (i, range) in self.row_ptr.windows(2).enumerate() {
            if range[0] == range[1] {
                continue;
            }
            let (columns, entries) = (
                &self.columns[range[0]..range[1]],
                &self.entries[range[0]..range[1]],
            );
            out[i] += columns
                .iter()
                .zip(entries)
                .map(|(&j, &(k, d))| k * q[j] + d * v[j])
                .sum::<f64>();
        }
    }
}

/// `1 / M_ii` of a diagonal, positive mass matrix; `None` otherwise.
pub(crate) fn inverse_diagonal_mass(model: &Model) -> Option<Vec<f64>> {
    let mut inv = vec![0.0; model.n_dofs()];
    for (i, j, v) in model.mass().iter() {
        if i != j && v != 0.0 {
            return None;
        }
        if i == j {
            inv[i] = 1.0 / v;
        }
    }
    inv.iter().all(|v| v.is_finite() && *v > 0.0).then_some(inv)
}

/// `Σ_j |A_ij|` per row.
pub(crate) fn absolute_row_sums(a: &SparseMatrix) -> Vec<f64> {
    let mut rows = vec![0.0; a.n()];
    for (i, _, v) in a.iter() {
        rows[i] += v.abs();
    }
    rows
}

/// Gershgorin's bound `max_i (Σ_j |A_ij| + Σ_e top_e |w_ei| Σ_j |w_ej|) / M_ii` on the
/// eigenvalues of `M⁻¹ (A + Σ_e top_e w_e w_eᵀ)`.
pub(crate) fn gershgorin(
    a: &SparseMatrix,
    inv_mass: &[f64],
    weights: &[&[(usize, f64)]],
    top: &[f64],
) -> f64 {
    let mut rows = absolute_row_sums(a);
    for (w, &t) in weights.iter().zip(top) {
        let sum: f64 = w.iter().map(|(_, w)| w.abs()).sum();
        for &(i, wi) in w.iter() {
            rows[i] += t * wi.abs() * sum;
        }
    }
    rows.iter()
        .zip(inv_mass)
        .map(|(r, m)| r * m)
        .fold(0.0, f64::max)
}

/// Gershgorin's bound on the fastest rate (1/s) of `model` linearised along `solution`,
/// `max_i Σ_j |D_ij| / M_ii + (Σ_j |K_ij| / M_ii)^½` with every element at its largest
/// tangent `|∂f/∂u|`, `|∂f/∂u̇|` on the orbit's samples: an explicit integrator's stable step
/// is at most a few times its inverse. `None` for a mass matrix that is not diagonal.
pub(crate) fn fastest_rate(model: &Model, solution: &crate::Solution) -> Option<f64> {
    let inv_mass = inverse_diagonal_mass(model)?;
    let (k_top, d_top) = largest_tangents(model, solution);
    let weights: Vec<&[(usize, f64)]> = model.elements().iter().map(|e| e.weights()).collect();
    let bound = |a, top: &[f64]| gershgorin(a, &inv_mass, &weights, top);
    Some(
        bound(model.structural_damping(), &d_top)
            + bound(model.structural_stiffness(), &k_top).sqrt(),
    )
}

/// Every element's largest `|∂f/∂u|` and `|∂f/∂u̇|` on `solution` (at its samples).
fn largest_tangents(model: &Model, solution: &crate::Solution) -> (Vec<f64>, Vec<f64>) {
    let basis = solution.basis();
    let nu = basis.subharmonic() as f64;
    let along = |w: &[(usize, f64)], theta: f64| {
        let u = w
            .iter()
            .map(|&(i, c)| c * solution.displacement(i, theta))
            .sum::<f64>();
        let du = w
            .iter()
            .map(|&(i, c)| c * solution.velocity(i, theta))
            .sum::<f64>();
        (u, du)
    };
    let finite = |x: f64| if x.is_finite() { x.abs() } else { 0.0 };
    model
        .elements()
        .iter()
        .map(|e| {
            (0..basis.samples()).fold((0.0f64, 0.0f64), |(k, d), j| {
                let theta = basis.theta(j);
                let (u, du) = along(e.weights(), theta);
                let (dk, dd) = e.law().derivatives(nu * theta, u, du);
                (k.max(finite(dk)), d.max(finite(dd)))
            })
        })
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass product equals `−M⁻¹ (K0 q + D0 v)` computed column by column, with
    /// patterns that differ and a repeated position.
    #[test]
    fn equals_the_column_products_scaled_by_the_mass() {
        let k0 = SparseMatrix::from_triplets(
            3,
            &[
                (0, 0, 2.0),
                (0, 1, -1.0),
                (1, 0, -1.0),
                (1, 1, 2.0),
                (2, 2, 5.0),
            ],
        );
        let d0 = SparseMatrix::from_triplets(3, &[(0, 2, 0.5), (1, 1, 0.25), (2, 0, -0.125)]);
        let inv_mass = [1.0, 0.5, 4.0];
        let (q, v) = ([1.0, -2.0, 3.0], [0.5, 4.0, -1.0]);
        let mut out = [0.0; 3];
        LinearRate::new(&k0, &d0, &inv_mass).apply(&q, &v, &mut out);
        let mut want = [0.0; 3];
        k0.mul_add(-1.0, &q, &mut want);
        d0.mul_add(-1.0, &v, &mut want);
        for i in 0..3 {
            assert!((out[i] - want[i] * inv_mass[i]).abs() < 1e-15, "{out:?}");
        }
        assert_eq!(out[0], -(2.0 + 2.0 - 0.5));
    }

    /// A banded matrix with a few far entries: dense diagonals for the band, compressed rows
    /// for the rest, the same product.
    #[test]
    fn band_and_far_entries_give_the_same_product() {
        let n = 40;
        let mut k = Vec::new();
        for i in 0..n {
            k.push((i, i, 2.0 + i as f64 * 0.1));
            if i + 1 < n {
                k.push((i, i + 1, -1.0));
                k.push((i + 1, i, -1.0 - 0.01 * i as f64));
            }
        }
        k.extend([(0, 39, 0.7), (39, 0, 0.7), (5, 30, -0.2)]);
        let d: Vec<_> = (0..n).map(|i| (i, i, 0.05)).chain([(3, 17, 0.3)]).collect();
        let (k0, d0) = (
            SparseMatrix::from_triplets(n, &k),
            SparseMatrix::from_triplets(n, &d),
        );
        let inv_mass: Vec<f64> = (0..n).map(|i| 1.0 / (1.0 + i as f64)).collect();
        let q: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let v: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).cos()).collect();
        let rate = LinearRate::new(&k0, &d0, &inv_mass);
        assert_eq!(rate.diagonals.len(), 3);
        assert_eq!(rate.columns.len(), 4);
        let mut out = vec![0.0; n];
        rate.apply(&q, &v, &mut out);
        let mut want = vec![0.0; n];
        k0.mul_add(-1.0, &q, &mut want);
        d0.mul_add(-1.0, &v, &mut want);
        for i in 0..n {
            assert!((out[i] - want[i] * inv_mass[i]).abs() < 1e-14, "{i}");
        }
    }
}
