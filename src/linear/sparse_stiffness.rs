//! The dynamic stiffness `Z_k = -(kΩ)² M + i kΩ D0 + K0` of a large model, held sparse and
//! factored by faer's sparse LU: one symbolic analysis (fill-reducing ordering, elimination
//! structure) for the common pattern of `M`, `D0`, `K0`, reused for every harmonic and every
//! speed; one numeric factorisation per harmonic.
//!
//! A drivetrain's matrices are chains and trees (a few nonzeros per row), so the factors stay
//! sparse and a factorisation costs `O(n)`, where the dense `LU` of
//! [`DynamicStiffness`](crate::harmonic::DynamicStiffness) costs `n³/3`.

use crate::error::{Error, Result};
use crate::model::SparseMatrix;
use crate::HarmonicBasis;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use faer::MatMut;
use num_complex::Complex64;

/// The pattern of `M`, `D0`, `K0` in compressed columns, with their values at each position.
#[derive(Debug, Clone)]
pub struct SparsePattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    m: Vec<f64>,
    d: Vec<f64>,
    k: Vec<f64>,
}

impl SparsePattern {
    /// The union of the nonzeros of `M`, `D0`, `K0` (and the diagonal, so that a structurally
    /// empty row is a clear singular error rather than a missing pivot).
    pub fn new(m: &SparseMatrix, d: &SparseMatrix, k: &SparseMatrix) -> Self {
        let n = m.n();
        // Tag each entry with its matrix, merge by position.
        let mut t: Vec<(usize, usize, u8, f64)> =
            Vec::with_capacity(m.nnz() + d.nnz() + k.nnz() + n);
        for (tag, a) in [(0u8, m), (1, d), (2, k)] {
            t.extend(a.iter().map(|(i, j, v)| (i, j, tag, v)));
        }
        t.extend((0..n).map(|i| (i, i, 3, 0.0)));
        t.sort_unstable_by_key(|&(i, j, _, _)| (j, i));
        let mut col_ptr = vec![0; n + 1];
        let (mut row_idx, mut mv, mut dv, mut kv) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut last = None;
        for (i, j, tag, v) in t {
            if last != Some((i, j)) {
                last = Some((i, j));
                row_idx.push(i);
                mv.push(0.0);
                dv.push(0.0);
                kv.push(0.0);
                col_ptr[j + 1] += 1;
            }
            let p = row_idx.len() - 1;
            match tag {
                0 => mv[p] += v,
                1 => dv[p] += v,
                2 => kv[p] += v,
                _ => {}
            }
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        Self {
            n,
            col_ptr,
            row_idx,
            m: mv,
            d: dv,
            k: kv,
        }
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Order n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The values of `Z(w) = -w² M + i w D0 + K0` on the pattern.
    fn values(&self, w: f64) -> Vec<Complex64> {
        (0..self.nnz())
            .map(|p| Complex64::new(self.k[p] - w * w * self.m[p], w * self.d[p]))
            .collect()
    }

    /// `out ← Z(w) x`.
    fn apply(&self, w: f64, x: &[Complex64], out: &mut [Complex64]) {
        out.fill(Complex64::default());
        for (j, xj) in x.iter().enumerate() {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let z = Complex64::new(self.k[p] - w * w * self.m[p], w * self.d[p]);
                out[self.row_idx[p]] += z * xj;
            }
        }
    }

    /// `out ← (dZ/dΩ) x` for `Z = -(κΩ)² M + i κΩ D0 + K0`: `(-2κ²Ω M + i κ D0) x`.
    fn apply_omega_derivative(
        &self,
        kappa: f64,
        omega: f64,
        x: &[Complex64],
        out: &mut [Complex64],
    ) {
        out.fill(Complex64::default());
        for (j, xj) in x.iter().enumerate() {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let dz =
                    Complex64::new(-2.0 * kappa * kappa * omega * self.m[p], kappa * self.d[p]);
                out[self.row_idx[p]] += dz * xj;
            }
        }
    }

    fn symbolic(&self) -> SymbolicSparseColMat<usize> {
        SymbolicSparseColMat::new_checked(
            self.n,
            self.n,
            self.col_ptr.clone(),
            None,
            self.row_idx.clone(),
        )
    }
}

/// `Z_k` for `k = 0..=H` factored by sparse LU on one symbolic analysis.
pub struct SparseDynamicStiffness {
    pattern: SparsePattern,
    symbolic: SymbolicLu<usize>,
    fundamental: f64,
    factors: Vec<Lu<usize, Complex64>>,
}

impl std::fmt::Debug for SparseDynamicStiffness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseDynamicStiffness")
            .field("n", &self.pattern.n)
            .field("nnz", &self.pattern.nnz())
            .field("harmonics", &self.factors.len().saturating_sub(1))
            .finish()
    }
}

/// Relative residual of a test solve above which `Z_k` counts as singular.
/// (normwise backward error `‖Z x - b‖ / (‖Z‖_F ‖x‖ + ‖b‖)`; a stable LU of a regular
/// matrix gives about 1e-16 whatever its condition, a singular one gives a non-finite or large
/// one).
const SINGULAR_RESIDUAL: f64 = 1e-8;

impl SparseDynamicStiffness {
    /// Analyses the pattern once and factors `Z_k` for every harmonic of `basis`; an error
    /// names the first singular harmonic.
    pub fn new(pattern: SparsePattern, basis: &HarmonicBasis) -> Result<Self> {
        let symbolic =
            SymbolicLu::try_new(pattern.symbolic().as_ref()).map_err(|e| Error::Solver {
                reason: format!("sparse LU analysis of the dynamic stiffness: {e:?}"),
            })?;
        let mut s = Self {
            pattern,
            symbolic,
            fundamental: basis.fundamental(),
            factors: Vec::new(),
        };
        s.refactor(basis)?;
        Ok(s)
    }

    /// Factors `Z_k` again for another Ω (same pattern, same symbolic analysis).
    pub fn refactor(&mut self, basis: &HarmonicBasis) -> Result<()> {
        self.fundamental = basis.fundamental();
        self.factors.clear();
        let n = self.pattern.n;
        let structure = self.pattern.symbolic();
        let mut test = vec![Complex64::default(); n];
        let mut back = vec![Complex64::default(); n];
        for k in 0..=basis.harmonics() {
            let w = k as f64 * self.fundamental;
            let z = SparseColMat::new(structure.clone(), self.pattern.values(w));
            let singular = |relative_pivot: f64| {
                let hint = if k == 0 {
                    "K0 is singular: a free rigid-body mode; ground it with a stiffness or fix \
                     the DOF"
                        .to_string()
                } else {
                    format!(
                        "an undamped natural frequency at {w} rad/s coincides with harmonic {k}; \
                         add damping or shift the speed"
                    )
                };
                Error::SingularDynamicStiffness {
                    harmonic: k,
                    omega: w,
                    relative_pivot,
                    hint,
                }
            };
            let lu = Lu::try_new_with_symbolic(self.symbolic.clone(), z.as_ref())
                .map_err(|_| singular(0.0))?;
            // A numerically singular Z_k shows in a test solve: 1, 2, ..., n.
            for (i, t) in test.iter_mut().enumerate() {
                *t = Complex64::new(1.0 + i as f64, 0.0);
            }
            let mut x = test.clone();
            lu.solve_in_place(MatMut::from_column_major_slice_mut(&mut x, n, 1));
            self.pattern.apply(w, &x, &mut back);
            let err: f64 = back
                .iter()
                .zip(&test)
                .map(|(a, b)| (a - b).norm_sqr())
                .sum::<f64>()
                .sqrt();
            let norm = |v: &[Complex64]| v.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
            let z_norm = z.val().iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
            let rel = err / (z_norm * norm(&x) + norm(&test));
            if !(rel.is_finite() && rel < SINGULAR_RESIDUAL) {
                return Err(singular(if rel.is_finite() { 1.0 / rel } else { 0.0 }));
            }
            self.factors.push(lu);
        }
        Ok(())
    }

    /// Order n.
    pub fn n(&self) -> usize {
        self.pattern.n
    }

    /// Harmonics H factored.
    pub fn harmonics(&self) -> usize {
        self.factors.len().saturating_sub(1)
    }

    /// `x ← Z_k⁻¹ x` for `columns` right-hand sides stored one after the other (column-major
    /// `n × columns`).
    pub fn solve_in_place(&self, k: usize, x: &mut [Complex64], columns: usize) {
        let n = self.pattern.n;
        self.factors[k].solve_in_place(MatMut::from_column_major_slice_mut(x, n, columns));
    }

    /// `out ← (dZ_k/dΩ) x`, where harmonic k oscillates at `k Ω / ν` (`kappa = k/ν`) and
    /// `omega` is Ω.
    pub fn apply_omega_derivative(
        &self,
        kappa: f64,
        omega: f64,
        x: &[Complex64],
        out: &mut [Complex64],
    ) {
        self.pattern.apply_omega_derivative(kappa, omega, x, out);
    }

    /// `out ← Z_k x`.
    pub fn apply(&self, k: usize, x: &[Complex64], out: &mut [Complex64]) {
        self.pattern.apply(k as f64 * self.fundamental, x, out);
    }
}

/// `true` if the symmetric `a` is positive definite (sparse Cholesky of its lower triangle
/// succeeds).
pub fn is_positive_definite(a: &SparseMatrix) -> bool {
    use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
    use faer::Side;
    let (col_ptr, row_idx, values) = a.parts();
    let structure =
        SymbolicSparseColMat::new_checked(a.n(), a.n(), col_ptr.to_vec(), None, row_idx.to_vec());
    let Ok(symbolic) = SymbolicLlt::try_new(structure.as_ref(), Side::Lower) else {
        return false;
    };
    let mat = SparseColMat::new(structure, values.to_vec());
    Llt::try_new_with_symbolic(symbolic, mat.as_ref(), Side::Lower).is_ok()
}
