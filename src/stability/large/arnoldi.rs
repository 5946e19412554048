//! The eigenvalues of largest modulus of an operator known only by its action: the Arnoldi
//! iteration.
//!
//! From a unit start vector `v_1`, `w = Φ v_j` is orthogonalised against `v_1 … v_j` (classical
//! Gram–Schmidt, twice), `h_ij = v_iᵀ w`, `h_{j+1,j} = ‖w‖`, `v_{j+1} = w / h_{j+1,j}`, so that
//! `Φ V_j = V_{j+1} H_{j+1,j}` with `H` upper Hessenberg. The eigenvalues of the square `H_j`
//! (Ritz values) converge to the outermost eigenvalues of `Φ` first; for a monodromy matrix
//! those are the multipliers that decide stability, while the many strongly damped modes crowd
//! near 0. The iteration stops when the leading Ritz values (modulus at least a tenth of the
//! largest, at most [`LEADING`]) agree to the tolerance between two checks [`CHECK_EVERY`]
//! vectors apart, when `h_{j+1,j}` vanishes (an invariant subspace: exact), or at the vector
//! limit. (A block of two start vectors, whose two actions per step could run side by side,
//! needed twice the vectors on the 1000-DOF chain's cluster of multipliers: the polynomial
//! degree, not the dimension, is what resolves a cluster.)

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
    /// The unit Ritz vector `y = V_k s` of `values[0]`, real and imaginary parts.
    pub(crate) leading_vector: (Vec<f64>, Vec<f64>),
    /// Its image `Φ y = V_{k+b} H s` by the Arnoldi relation (no further action).
    pub(crate) leading_image: (Vec<f64>, Vec<f64>),
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
    let (mut values, mut change, mut done) = (Vec::new(), f64::INFINITY, 0);
    for j in 0..m {
        apply(&basis[j], &mut w)?;
        let mut column = vec![0.0; j + 1];
        orthogonalise(&basis, &mut w, &mut column);
        let beta = norm(&w);
        for (i, c) in column.iter().enumerate() {
            h[(i, j)] = *c;
        }
        h[(j + 1, j)] = beta;
        done = j + 1;
        let scale = column.iter().fold(beta, |a, c| a.max(c.abs()));
        let invariant = beta <= 1e-14 * scale.max(f64::MIN_POSITIVE);
        // v_{j+1} before any stop: the relation Φ V_k = V_{k+1} H stays whole for the Ritz
        // vector's image.
        if !invariant {
            basis.push(w.iter().map(|v| v / beta).collect());
        }
        if invariant || done % CHECK_EVERY == 0 || done == m {
            values = ritz_values(&h, done);
            change = match &previous {
                _ if invariant => 0.0,
                Some(p) => distance(&values, p),
                None => f64::INFINITY,
            };
            let top = values.first().map_or(0.0, |v| v.norm());
            if invariant || change <= tol * top.max(f64::MIN_POSITIVE) {
                break;
            }
            previous = Some(values.clone());
        }
    }
    let (leading_vector, leading_image) = ritz_vector(&h, done, &basis, values.first().copied());
    Ok(Ritz {
        values,
        vectors: done,
        change,
        leading_vector,
        leading_image,
    })
}

/// `w ← w − Σ v_i (v_iᵀ w)` over `basis`, twice; the coefficients added to `column`.
fn orthogonalise(basis: &[Vec<f64>], w: &mut [f64], column: &mut [f64]) {
    for _ in 0..2 {
        for (i, v) in basis.iter().enumerate() {
            let c: f64 = v.iter().zip(w.iter()).map(|(a, b)| a * b).sum();
            column[i] += c;
            w.iter_mut().zip(v).for_each(|(w, v)| *w -= c * v);
        }
    }
}

/// Real and imaginary parts of a complex vector.
type Pair = (Vec<f64>, Vec<f64>);

/// The unit vector `y = V_k s` and its image `Φ y = V H s`, `s` the eigenvector of `H_k` for
/// `theta` by two steps of inverse iteration (zero vectors if there is no value).
fn ritz_vector(
    h: &DMatrix<f64>,
    k: usize,
    basis: &[Vec<f64>],
    theta: Option<Complex64>,
) -> (Pair, Pair) {
    let dim = basis.first().map_or(0, Vec::len);
    let zero = || (vec![0.0; dim], vec![0.0; dim]);
    let Some(theta) = theta.filter(|_| k > 0) else {
        return (zero(), zero());
    };
    let shift = theta + Complex64::new(1e-10, 1e-10) * theta.norm().max(1e-300);
    let a = DMatrix::<Complex64>::from_fn(k, k, |i, j| {
        Complex64::from(h[(i, j)]) - if i == j { shift } else { 0.0.into() }
    });
    let lu = a.lu();
    let mut s = nalgebra::DVector::<Complex64>::from_element(k, Complex64::from(1.0));
    for _ in 0..2 {
        s = lu.solve(&s).unwrap_or(s);
        let n = s.norm();
        if n.is_finite() && n > 0.0 {
            s /= Complex64::from(n);
        }
    }
    let rows = basis.len().min(h.nrows());
    let hs: Vec<Complex64> = (0..rows)
        .map(|i| (0..k).map(|j| s[j] * h[(i, j)]).sum())
        .collect();
    let combine = |c: &[Complex64]| -> Pair {
        let (mut re, mut im) = zero();
        for (c, v) in c.iter().zip(basis) {
            for ((r, i), x) in re.iter_mut().zip(im.iter_mut()).zip(v) {
                *r += c.re * x;
                *i += c.im * x;
            }
        }
        (re, im)
    };
    let (y, image) = (combine(s.as_slice()), combine(&hs));
    // y is a unit vector already (V orthonormal, ‖s‖ = 1).
    (y, image)
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
        let a = &a;
        let ritz = leading_eigenvalues(
            n,
            |x, out| {
                out.copy_from_slice((a * nalgebra::DVector::from_column_slice(x)).as_slice());
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
        // The Ritz vector is the eigenvector: ‖A y − θ y‖ small for the unit y.
        let (re, im) = &ritz.leading_vector;
        let y = nalgebra::DVector::from_iterator(
            n,
            re.iter().zip(im).map(|(r, i)| Complex64::new(*r, *i)),
        );
        let ay = a.map(Complex64::from) * &y;
        let residual = (ay - &y * got).norm();
        assert!(
            (y.norm() - 1.0).abs() < 1e-12 && residual < 1e-8,
            "{residual}"
        );
    }
}
