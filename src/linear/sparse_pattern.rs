//! The common sparsity pattern of `M`, `D0`, `K0` (compressed columns) with their values, from
//! which `Z_k = -(kΩ)² M + i kΩ D0 + K0` is formed at any frequency without reassembly; and the
//! sparse Cholesky test of a mass matrix.

use crate::model::SparseMatrix;
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use num_complex::Complex64;

/// The pattern of `M`, `D0`, `K0` in compressed columns, with their values at each position.
#[derive(Debug, Clone)]
pub struct SparsePattern {
    pub(super) n: usize,
    pub(super) col_ptr: Vec<usize>,
    pub(super) row_idx: Vec<usize>,
    pub(super) m: Vec<f64>,
    pub(super) d: Vec<f64>,
    pub(super) k: Vec<f64>,
    /// Hysteretic damping `H` (`+ i H` at every `w > 0`); empty without it.
    pub(super) h: Vec<f64>,
    /// `(Σ k², Σ k m, Σ m², Σ d², Σ d h, Σ h²)` over the entries, for
    /// [`values_norm`](Self::values_norm).
    sums: [f64; 6],
}

impl SparsePattern {
    /// The union of the nonzeros of `M`, `D0`, `K0` (and the diagonal, so that a structurally
    /// empty row is a clear singular error rather than a missing pivot).
    pub fn new(m: &SparseMatrix, d: &SparseMatrix, k: &SparseMatrix) -> Self {
        Self::with_hysteretic(m, d, k, &SparseMatrix::zeros(m.n()))
    }

    /// [`SparsePattern::new`] with hysteretic damping `H`: `Z(w) = -w² M + i (w D0 + H) + K0`
    /// at `w > 0` (`H` has no static part).
    pub fn with_hysteretic(
        m: &SparseMatrix,
        d: &SparseMatrix,
        k: &SparseMatrix,
        h: &SparseMatrix,
    ) -> Self {
        let n = m.n();
        // Tag each entry with its matrix, merge by position.
        let mut t: Vec<(usize, usize, u8, f64)> =
            Vec::with_capacity(m.nnz() + d.nnz() + k.nnz() + h.nnz() + n);
        for (tag, a) in [(0u8, m), (1, d), (2, k), (4, h)] {
            t.extend(a.iter().map(|(i, j, v)| (i, j, tag, v)));
        }
        t.extend((0..n).map(|i| (i, i, 3, 0.0)));
        t.sort_unstable_by_key(|&(i, j, _, _)| (j, i));
        let mut col_ptr = vec![0; n + 1];
        let (mut row_idx, mut mv, mut dv, mut kv, mut hv) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut last = None;
        for (i, j, tag, v) in t {
            if last != Some((i, j)) {
                last = Some((i, j));
                row_idx.push(i);
                mv.push(0.0);
                dv.push(0.0);
                kv.push(0.0);
                hv.push(0.0);
                col_ptr[j + 1] += 1;
            }
            let p = row_idx.len() - 1;
            match tag {
                0 => mv[p] += v,
                1 => dv[p] += v,
                2 => kv[p] += v,
                4 => hv[p] += v,
                _ => {}
            }
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let sums = [
            dot(&kv, &kv),
            dot(&kv, &mv),
            dot(&mv, &mv),
            dot(&dv, &dv),
            dot(&dv, &hv),
            dot(&hv, &hv),
        ];
        if hv.iter().all(|v| *v == 0.0) {
            hv.clear();
        }
        Self {
            n,
            col_ptr,
            row_idx,
            m: mv,
            d: dv,
            k: kv,
            h: hv,
            sums,
        }
    }

    /// `true` if `M`, `D0`, `K0` (and `H`) are symmetric to rounding (1e-13 of each one's largest
    /// entry: an assembly sums `(i, j)` and `(j, i)` in different orders).
    pub(super) fn is_symmetric(&self) -> bool {
        let n = self.n;
        let amax = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let tol = [amax(&self.m), amax(&self.d), amax(&self.k), amax(&self.h)].map(|a| 1e-13 * a);
        let h = |p: usize| self.h.get(p).copied().unwrap_or(0.0);
        (0..n).all(|j| {
            (self.col_ptr[j]..self.col_ptr[j + 1]).all(|p| {
                let i = self.row_idx[p];
                let s = self.col_ptr[i]..self.col_ptr[i + 1];
                match self.row_idx[s.clone()].binary_search(&j) {
                    Ok(q) => {
                        let q = s.start + q;
                        (self.m[q] - self.m[p]).abs() <= tol[0]
                            && (self.d[q] - self.d[p]).abs() <= tol[1]
                            && (self.k[q] - self.k[p]).abs() <= tol[2]
                            && (h(q) - h(p)).abs() <= tol[3]
                    }
                    Err(_) => false,
                }
            })
        })
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Order n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The values of `Z(w) + s M = -(w² - s) M + i w D0 + K0` on the pattern.
    pub(super) fn values(&self, w: f64, s: f64) -> Vec<Complex64> {
        (0..self.nnz()).map(|p| self.value(p, w, s)).collect()
    }

    /// Entry `p` of [`values`](Self::values).
    #[inline]
    pub(super) fn value(&self, p: usize, w: f64, s: f64) -> Complex64 {
        Complex64::new(self.k[p] - (w * w - s) * self.m[p], self.imaginary(p, w))
    }

    /// `w D0 + H` at entry `p` (`H` at `w > 0` only).
    #[inline]
    fn imaginary(&self, p: usize, w: f64) -> f64 {
        match self.h.get(p) {
            Some(h) if w > 0.0 => w * self.d[p] + h,
            _ => w * self.d[p],
        }
    }

    /// `‖Z(w) + s M‖_F` without forming the values: with `a = w² - s`,
    /// `Σ |k - a m + i w d|² = Σk² - 2a Σkm + a² Σm² + w² Σd²` (the sums kept; rounding of
    /// about 1e-16 of `‖K‖² + a²‖M‖²`, enough for the backward error it scales). Where the
    /// sums overflow (entries beyond 1e154), from the values, scaled; NaN if a value is not
    /// finite.
    pub(super) fn values_norm(&self, w: f64, s: f64) -> f64 {
        let [kk, km, mm, dd, dh, hh] = self.sums;
        let a = w * w - s;
        let mut sum = kk - 2.0 * a * km + a * a * mm + w * w * dd;
        if w > 0.0 {
            sum += 2.0 * w * dh + hh;
        }
        if sum.is_finite() {
            return sum.max(0.0).sqrt();
        }
        let mut top = 0.0_f64;
        for p in 0..self.nnz() {
            let v = self.value(p, w, s);
            if !(v.re.is_finite() && v.im.is_finite()) {
                return f64::NAN;
            }
            top = top.max(v.re.abs()).max(v.im.abs());
        }
        let scaled: f64 = (0..self.nnz())
            .map(|p| (self.value(p, w, s) / top).norm_sqr())
            .sum();
        top * scaled.sqrt()
    }

    /// `out ← (Z(w) + s M) x`.
    pub(super) fn apply(&self, w: f64, s: f64, x: &[Complex64], out: &mut [Complex64]) {
        out.fill(Complex64::default());
        for (j, xj) in x.iter().enumerate() {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let z = self.value(p, w, s);
                out[self.row_idx[p]] += z * xj;
            }
        }
    }

    /// `out ← (dZ/dΩ) x` for `Z = -(κΩ)² M + i κΩ D0 + K0`: `(-2κ²Ω M + i κ D0) x`.
    pub(super) fn apply_omega_derivative(
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

    pub(super) fn symbolic(&self) -> SymbolicSparseColMat<usize> {
        SymbolicSparseColMat::new_checked(
            self.n,
            self.n,
            self.col_ptr.clone(),
            None,
            self.row_idx.clone(),
        )
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

#[cfg(test)]
mod tests {
    use super::SparsePattern;
    use crate::model::SparseMatrix;

    /// The kept sums give the values' norm; beyond 1e154 the values themselves (finite, no
    /// spurious overflow); a value that is not finite gives NaN.
    #[test]
    fn the_norm_from_the_sums_and_beyond_them() {
        let pattern = |scale: f64| {
            let m = SparseMatrix::from_triplets(2, &[(0, 0, 2.0), (1, 1, 1.0)]);
            let d = SparseMatrix::from_triplets(2, &[(0, 0, 0.3)]);
            let k = SparseMatrix::from_triplets(
                2,
                &[
                    (0, 0, 5.0 * scale),
                    (0, 1, -scale),
                    (1, 0, -scale),
                    (1, 1, 4.0 * scale),
                ],
            );
            SparsePattern::new(&m, &d, &k)
        };
        let direct = |p: &SparsePattern, w: f64, s: f64| {
            p.values(w, s)
                .iter()
                .map(|v| v.norm_sqr())
                .sum::<f64>()
                .sqrt()
        };
        let p = pattern(1.0);
        for (w, s) in [(0.0, 0.0), (1.3, 0.0), (0.7, 0.25), (40.0, 0.0)] {
            let (a, b) = (p.values_norm(w, s), direct(&p, w, s));
            assert!((a - b).abs() <= 1e-13 * b, "{w} {s}: {a} {b}");
        }
        let huge = pattern(1e160);
        let n = huge.values_norm(1.0, 0.0);
        assert!(
            n.is_finite() && (n / 1e160 - 43.0_f64.sqrt()).abs() < 1e-12,
            "{n}"
        );
        assert!(p.values_norm(f64::INFINITY, 0.0).is_nan());
    }
}
