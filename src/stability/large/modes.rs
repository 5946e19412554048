//! The lowest undamped modes of `(K0, M)`: `K0 φ = λ M φ`, `λ = ω²`, below a cut-off.
//!
//! Small models (at most [`DENSE_MODES`] DOFs): the dense symmetric eigenproblem
//! `L⁻¹ K0 L⁻ᵀ z = λ z`, `M = L Lᵀ`, `φ = L⁻ᵀ z`.
//!
//! Large models: shift-invert subspace iteration (Bathe & Wilson, *Numerical Methods in Finite
//! Element Analysis*, 1976, ch. 10) on a block of `p` vectors,
//! `Y = (K0 + σM)⁻¹ M X`, then Rayleigh–Ritz on `(YᵀK0Y, YᵀMY)`, `X ← Y Z`, with one sparse
//! Cholesky factorisation of `K0 + σM`. The Ritz values converge to the `p` lowest eigenvalues
//! from above, mode `i` at the rate `(λ_i + σ)/(λ_{p+1} + σ)` per iteration. The shift
//! `σ > 0` makes a free-free model (rigid-body modes, singular `K0`) factorisable; its rigid
//! modes come out with `λ ≈ 0`. The block grows (doubles) until the first Ritz value beyond
//! the cut-off has converged with a guard of vectors above it, so no mode below the cut-off is
//! missed.

use crate::error::{Error, Result};
use crate::model::SparseMatrix;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::{MatMut, Side};
use nalgebra::DMatrix;

/// Largest model whose modes come from the dense eigenproblem.
pub(crate) const DENSE_MODES: usize = 300;

/// Relative residual `‖K0 φ - λ M φ‖ / ‖K0 φ + σ M φ‖` below which a Ritz pair has converged.
const RITZ_TOL: f64 = 1e-8;

/// Modes `φ_i` (columns, M-orthonormal) with `λ_i = ω_i²` ascending.
pub(crate) struct Modes {
    pub(crate) values: Vec<f64>,
    pub(crate) vectors: DMatrix<f64>,
}

/// The modes of `(k0, m)` with `λ <= cutoff` (every mode for an infinite cut-off), shift
/// `shift` for the factorisation; the factorisation of `K0 + σM` comes back for the
/// attachment modes.
pub(crate) fn lowest_modes(
    k0: &SparseMatrix,
    m: &SparseMatrix,
    cutoff: f64,
    shift: f64,
) -> Result<(Modes, ShiftedStiffness)> {
    let factor = ShiftedStiffness::new(k0, m, shift)?;
    let n = k0.n();
    let modes = if n <= DENSE_MODES || cutoff.is_infinite() {
        dense_modes(k0, m, cutoff)?
    } else {
        subspace_iteration(k0, m, cutoff, &factor)?
    };
    Ok((modes, factor))
}

/// The dense generalized eigenproblem (all n modes, then those below the cut-off).
fn dense_modes(k0: &SparseMatrix, m: &SparseMatrix, cutoff: f64) -> Result<Modes> {
    let n = k0.n();
    let chol = m.to_dense().cholesky().ok_or_else(not_positive)?;
    let l_inv = chol.l().try_inverse().ok_or_else(not_positive)?;
    let a = &l_inv * k0.to_dense() * l_inv.transpose();
    let eig = ((&a + a.transpose()) * 0.5).symmetric_eigen();
    let mut order: Vec<usize> = (0..n).filter(|&i| eig.eigenvalues[i] <= cutoff).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let lt = l_inv.transpose();
    let mut vectors = DMatrix::zeros(n, order.len());
    for (c, &i) in order.iter().enumerate() {
        vectors.set_column(c, &(&lt * eig.eigenvectors.column(i)));
    }
    Ok(Modes {
        values: order.iter().map(|&i| eig.eigenvalues[i]).collect(),
        vectors,
    })
}

/// Shift-invert subspace iteration with a growing block.
fn subspace_iteration(
    k0: &SparseMatrix,
    m: &SparseMatrix,
    cutoff: f64,
    factor: &ShiftedStiffness,
) -> Result<Modes> {
    let n = k0.n();
    let mut p = 16.min(n);
    // A deterministic start: smooth and rough vectors (a linear congruential sequence).
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut random = |rows: usize, cols: usize| {
        DMatrix::from_fn(rows, cols, |_, _| {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
    };
    let mut x = random(n, p);
    for _ in 0..200 {
        let mut y = crate::stability::system::sparse_times(m, &x);
        factor.solve_in_place(&mut y);
        // Columns scaled by 1/(λ + σ) span a wide range (a free or softly grounded model):
        // M-orthonormalise them in order before the Ritz step.
        m_orthonormalise(m, &mut y, &mut random);
        let (values, z) = rayleigh_ritz(k0, m, &y)?;
        x = &y * z;
        let below = values.iter().filter(|&&v| v <= cutoff).count();
        // Guard: a quarter of the block (at least 4 vectors) above the first mode beyond the
        // cut-off, so that its rate of convergence is good.
        let guard = (p / 4).max(4);
        if below + 1 + guard > p && p < n {
            let extra = (2 * p).min(n) - p;
            p += extra;
            x = DMatrix::from_fn(n, p, |i, j| if j < p - extra { x[(i, j)] } else { 0.0 });
            let fresh = random(n, extra);
            x.columns_mut(p - extra, extra).copy_from(&fresh);
            continue;
        }
        let check = (below + 1).min(p);
        let residual = (0..check)
            .map(|j| relative_residual(k0, m, x.column(j).as_slice(), values[j], factor.shift))
            .fold(0.0, f64::max);
        if residual <= RITZ_TOL {
            return Ok(Modes {
                values: values[..below].to_vec(),
                vectors: x.columns(0, below).into_owned(),
            });
        }
    }
    Err(Error::Solver {
        reason: "the subspace iteration for the lowest modes of (K0, M) did not converge in 200 iterations".into(),
    })
}

/// Gram–Schmidt in the M inner product, twice per column, in column order; a column that
/// lies in the span of the previous ones is replaced by a fresh random one.
fn m_orthonormalise(
    m: &SparseMatrix,
    y: &mut DMatrix<f64>,
    random: &mut impl FnMut(usize, usize) -> DMatrix<f64>,
) {
    let n = y.nrows();
    let mut mx = nalgebra::DVector::zeros(n);
    for j in 0..y.ncols() {
        for attempt in 0..3 {
            let mut x = y.column(j).into_owned();
            let norm0 = m_norm(m, x.as_slice());
            for _ in 0..2 {
                // x -= Y_{<j} (Y_{<j}ᵀ M x), the previous columns at once.
                mx.fill(0.0);
                m.mul_add(1.0, x.as_slice(), mx.as_mut_slice());
                if j > 0 {
                    let previous = y.columns(0, j);
                    let c = previous.tr_mul(&mx);
                    x.gemv(-1.0, &previous, &c, 1.0);
                }
            }
            let norm = m_norm(m, x.as_slice());
            if norm > 1e-10 * norm0 && norm.is_finite() && norm > 0.0 || attempt == 2 {
                y.set_column(j, &(x / norm.max(f64::MIN_POSITIVE)));
                break;
            }
            y.set_column(j, &random(n, 1).column(0));
        }
    }
}

fn m_norm(m: &SparseMatrix, x: &[f64]) -> f64 {
    let mut mx = vec![0.0; x.len()];
    m.mul_add(1.0, x, &mut mx);
    x.iter()
        .zip(&mx)
        .map(|(a, b)| a * b)
        .sum::<f64>()
        .max(0.0)
        .sqrt()
}

/// The Ritz pairs of `(k0, m)` on the columns of `y`: values ascending, `Z` with `YZ`
/// M-orthonormal.
fn rayleigh_ritz(
    k0: &SparseMatrix,
    m: &SparseMatrix,
    y: &DMatrix<f64>,
) -> Result<(Vec<f64>, DMatrix<f64>)> {
    let ky = y.transpose() * crate::stability::system::sparse_times(k0, y);
    let my = y.transpose() * crate::stability::system::sparse_times(m, y);
    let my = (&my + my.transpose()) * 0.5;
    let p = y.ncols();
    let chol = my.cholesky().ok_or_else(|| Error::Solver {
        reason: "the subspace iteration's block lost its rank".into(),
    })?;
    let l_inv = chol.l().try_inverse().ok_or_else(not_positive)?;
    let a = &l_inv * ky * l_inv.transpose();
    let eig = ((&a + a.transpose()) * 0.5).symmetric_eigen();
    let mut order: Vec<usize> = (0..p).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let lt = l_inv.transpose();
    let mut z = DMatrix::zeros(p, p);
    for (c, &i) in order.iter().enumerate() {
        z.set_column(c, &(&lt * eig.eigenvectors.column(i)));
    }
    Ok((order.iter().map(|&i| eig.eigenvalues[i]).collect(), z))
}

/// `‖K0 φ - λ M φ‖ / ‖K0 φ + σ M φ‖`.
fn relative_residual(
    k0: &SparseMatrix,
    m: &SparseMatrix,
    phi: &[f64],
    lambda: f64,
    shift: f64,
) -> f64 {
    let n = phi.len();
    let (mut kp, mut mp) = (vec![0.0; n], vec![0.0; n]);
    k0.mul_add(1.0, phi, &mut kp);
    m.mul_add(1.0, phi, &mut mp);
    let (mut r, mut s) = (0.0, 0.0);
    for i in 0..n {
        r += (kp[i] - lambda * mp[i]).powi(2);
        s += (kp[i] + shift * mp[i]).powi(2);
    }
    (r / s).sqrt()
}

fn not_positive() -> Error {
    Error::MassNotPositiveDefinite {
        reason: "Cholesky factorisation failed in the modal reduction".into(),
    }
}

/// The sparse Cholesky factorisation of `K0 + σM`.
pub(crate) struct ShiftedStiffness {
    llt: Llt<usize, f64>,
    /// σ.
    pub(crate) shift: f64,
    n: usize,
}

impl ShiftedStiffness {
    /// Factors `k0 + shift m` (both symmetric).
    pub(crate) fn new(k0: &SparseMatrix, m: &SparseMatrix, shift: f64) -> Result<Self> {
        let n = k0.n();
        let t: Vec<(usize, usize, f64)> = k0
            .iter()
            .chain(m.iter().map(|(i, j, v)| (i, j, shift * v)))
            .filter(|&(i, j, _)| i >= j)
            .collect();
        let a = SparseMatrix::from_triplets(n, &t);
        let (col_ptr, row_idx, values) = a.parts();
        let structure =
            SymbolicSparseColMat::new_checked(n, n, col_ptr.to_vec(), None, row_idx.to_vec());
        let unsupported = || {
            Error::Solver {
            reason: format!(
                "K0 + σM (σ = {shift:e}) is not positive definite: the reduced Floquet analysis needs a positive semi-definite K0 (use the dense method)"
            ),
        }
        };
        let symbolic =
            SymbolicLlt::try_new(structure.as_ref(), Side::Lower).map_err(|_| unsupported())?;
        let mat = SparseColMat::new(structure, values.to_vec());
        let llt = Llt::try_new_with_symbolic(symbolic, mat.as_ref(), Side::Lower)
            .map_err(|_| unsupported())?;
        Ok(Self { llt, shift, n })
    }

    /// `X ← (K0 + σM)⁻¹ X`, column by column.
    pub(crate) fn solve_in_place(&self, x: &mut DMatrix<f64>) {
        let cols = x.ncols();
        self.llt.solve_in_place(MatMut::from_column_major_slice_mut(
            x.as_mut_slice(),
            self.n,
            cols,
        ));
    }
}
