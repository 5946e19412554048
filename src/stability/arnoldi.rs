//! The eigenvalues of largest modulus of an operator known only by its action: the Arnoldi
//! iteration.
//!
//! From a unit start vector `v_1`, `w = Φ v_j` is orthogonalised against `v_1 … v_j` (classical
//! Gram–Schmidt, twice), `h_ij = v_iᵀ w`, `h_{j+1,j} = ‖w‖`, `v_{j+1} = w / h_{j+1,j}`, so that
//! `Φ V_j = V_j H_j + h_{j+1,j} v_{j+1} e_jᵀ` with `H_j` upper Hessenberg. The eigenvalues of
//! `H_j` (Ritz values) converge to the outermost eigenvalues of `Φ` first; for a monodromy
//! matrix those are the multipliers that decide stability, while the many strongly damped
//! modes crowd near 0. The iteration stops when the leading Ritz values (modulus at least a
//! tenth of the largest, at most [`LEADING`]) agree to the tolerance between two checks
//! [`CHECK_EVERY`] vectors apart, when `h_{j+1,j}` vanishes (an invariant subspace: exact), or
//! at the vector limit.

use crate::error::Result;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Ritz values compared for convergence, at most.
pub(crate) const LEADING: usize = 8;

/// Vectors between two convergence checks.
const CHECK_EVERY: usize = 4;

/// The outcome of [`leading_eigenvalues`].
#[derive(Debug, Clone)]
pub(crate) struct Ritz {
    /// Ritz values, largest modulus first.
    pub(crate) values: Vec<Complex64>,
    /// Vectors of the Krylov space (applications of the operator).
    pub(crate) vectors: usize,
    /// The largest change of the leading Ritz values between the last two checks (0 for an
    /// invariant subspace).
    pub(crate) change: f64,
}

/// The leading eigenvalues of the operator `apply` (`out = Φ x`, dimension `dim`) from the
/// start vector `start`, with at most `max_vectors` applications, to the tolerance `tol`
/// (relative to the largest modulus).
pub(crate) fn leading_eigenvalues(
    dim: usize,
    mut apply: impl FnMut(&[f64], &mut [f64]) -> Result<()>,
    start: &[f64],
    max_vectors: usize,
    tol: f64,
) -> Result<Ritz> {
    let m = max_vectors.min(dim).max(1);
    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(m + 1);
    let norm0 = norm(start);
    basis.push(start.iter().map(|v| v / norm0).collect());
    let mut h = DMatrix::<f64>::zeros(m + 1, m);
    let mut w = vec![0.0; dim];
    let mut previous: Option<Vec<Complex64>> = None;
    let mut last = Ritz {
        values: Vec::new(),
        vectors: 0,
        change: f64::INFINITY,
    };
    for j in 0..m {
        apply(&basis[j], &mut w)?;
        for _ in 0..2 {
            for (i, v) in basis.iter().enumerate() {
                let c: f64 = v.iter().zip(&w).map(|(a, b)| a * b).sum();
                h[(i, j)] += c;
                w.iter_mut().zip(v).for_each(|(w, v)| *w -= c * v);
            }
        }
        let beta = norm(&w);
        h[(j + 1, j)] = beta;
        let scale = (0..=j).map(|i| h[(i, j)].abs()).fold(beta, f64::max);
        let invariant = beta <= 1e-14 * scale.max(f64::MIN_POSITIVE);
        if invariant || (j + 1) % CHECK_EVERY == 0 || j + 1 == m {
            let values = ritz_values(&h, j + 1);
            let change = match &previous {
                _ if invariant => 0.0,
                Some(p) => distance(&values, p),
                None => f64::INFINITY,
            };
            let top = values.first().map_or(0.0, |v| v.norm());
            last = Ritz {
                values: values.clone(),
                vectors: j + 1,
                change,
            };
            if invariant || change <= tol * top.max(f64::MIN_POSITIVE) {
                return Ok(last);
            }
            previous = Some(values);
        }
        basis.push(w.iter().map(|v| v / beta).collect());
    }
    Ok(last)
}

/// The eigenvalues of the leading `k × k` block of `h`, largest modulus first.
fn ritz_values(h: &DMatrix<f64>, k: usize) -> Vec<Complex64> {
    let block = h.view((0, 0), (k, k)).clone_owned();
    let mut values: Vec<Complex64> = block.complex_eigenvalues().iter().copied().collect();
    values.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    values
}

/// The largest distance of a leading value of `a` (modulus at least a tenth of the largest, at
/// most [`LEADING`]) to the nearest of `b`.
fn distance(a: &[Complex64], b: &[Complex64]) -> f64 {
    let top = a.first().map_or(0.0, |v| v.norm());
    a.iter()
        .take(LEADING)
        .filter(|v| v.norm() >= 0.1 * top)
        .map(|v| {
            b.iter()
                .map(|w| (v - w).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A block-diagonal matrix with known eigenvalues: the leading ones are found long before
    /// the dimension is exhausted.
    #[test]
    fn finds_the_leading_eigenvalues_of_a_known_matrix() {
        let n = 200;
        // 2 × 2 rotation-scaling blocks r (cos φ, sin φ) with r = 0.97^k.
        let mut a = DMatrix::<f64>::zeros(n, n);
        for k in 0..n / 2 {
            let (r, phi) = (0.8_f64.powi(k as i32) * 1.05, 0.3 + 0.1 * k as f64);
            let (c, s) = (r * phi.cos(), r * phi.sin());
            a[(2 * k, 2 * k)] = c;
            a[(2 * k, 2 * k + 1)] = -s;
            a[(2 * k + 1, 2 * k)] = s;
            a[(2 * k + 1, 2 * k + 1)] = c;
        }
        let start: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.37).sin()).collect();
        let ritz = leading_eigenvalues(
            n,
            |x, out| {
                out.copy_from_slice((&a * nalgebra::DVector::from_column_slice(x)).as_slice());
                Ok(())
            },
            &start,
            80,
            1e-10,
        )
        .unwrap();
        assert!(ritz.vectors < 80, "{} vectors", ritz.vectors);
        let want = Complex64::from_polar(1.05, 0.3);
        let got = ritz.values[0];
        assert!((got.norm() - 1.05).abs() < 1e-9, "{got}");
        assert!((got.im.abs() - want.im).abs() < 1e-9, "{got}");
        assert!(
            (ritz.values[2].norm() - 0.84).abs() < 1e-8,
            "{:?}",
            &ritz.values[..4]
        );
    }
}
