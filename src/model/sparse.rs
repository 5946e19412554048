//! Real sparse matrices in compressed columns: how a model holds `M`, `D`, `K`, so that a
//! drivetrain with 10⁵ DOFs (a few nonzeros per row) costs megabytes, not the 80 GB of a
//! dense matrix.

use nalgebra::DMatrix;

/// A square real matrix in compressed sparse columns: sorted row indices, no duplicates.
///
/// ```
/// use hbal::model::SparseMatrix;
/// // Repeated positions add up, as in FE assembly.
/// let a = SparseMatrix::from_triplets(2, &[(0, 0, 1.0), (1, 0, -1.0), (0, 0, 1.0), (1, 1, 3.0)]);
/// assert_eq!(a.nnz(), 3);
/// assert_eq!(a.get(0, 0), 2.0);
/// assert_eq!(a.to_dense()[(1, 0)], -1.0);
/// let mut y = [0.0; 2];
/// a.mul_add(1.0, &[1.0, 1.0], &mut y);
/// assert_eq!(y, [2.0, 2.0]);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct SparseMatrix {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

impl SparseMatrix {
    /// The `n × n` zero matrix.
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            col_ptr: vec![0; n + 1],
            row_idx: Vec::new(),
            values: Vec::new(),
        }
    }

    /// Assembles `(row, column, value)` triplets (indices below `n`, checked by the caller);
    /// repeated positions add up.
    pub fn from_triplets(n: usize, triplets: &[(usize, usize, f64)]) -> Self {
        let mut t: Vec<(usize, usize, f64)> = triplets.to_vec();
        t.sort_unstable_by_key(|&(i, j, _)| (j, i));
        let mut col_ptr = vec![0; n + 1];
        let mut row_idx = Vec::with_capacity(t.len());
        let mut values: Vec<f64> = Vec::with_capacity(t.len());
        let mut last = None;
        for (i, j, v) in t {
            if last == Some((i, j)) {
                *values.last_mut().expect("a previous entry") += v;
                continue;
            }
            last = Some((i, j));
            row_idx.push(i);
            values.push(v);
            col_ptr[j + 1] += 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        Self {
            n,
            col_ptr,
            row_idx,
            values,
        }
    }

    /// The nonzeros of a dense square matrix.
    pub fn from_dense(a: &DMatrix<f64>) -> Self {
        let n = a.nrows();
        let t: Vec<(usize, usize, f64)> = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .filter(|&(i, j)| a[(i, j)] != 0.0)
            .map(|(i, j)| (i, j, a[(i, j)]))
            .collect();
        Self::from_triplets(n, &t)
    }

    /// Order n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Stored entries.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// Entry `(i, j)` (zero where none is stored).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let s = self.col_ptr[j]..self.col_ptr[j + 1];
        match self.row_idx[s.clone()].binary_search(&i) {
            Ok(p) => self.values[s.start + p],
            Err(_) => 0.0,
        }
    }

    /// The stored entries as `(row, column, value)`, column by column.
    pub fn iter(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        (0..self.n).flat_map(move |j| {
            (self.col_ptr[j]..self.col_ptr[j + 1])
                .map(move |p| (self.row_idx[p], j, self.values[p]))
        })
    }

    /// `y += s A x`.
    pub fn mul_add(&self, s: f64, x: &[f64], y: &mut [f64]) {
        for (j, xj) in x.iter().enumerate().take(self.n) {
            let sx = s * xj;
            if sx == 0.0 {
                continue;
            }
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                y[self.row_idx[p]] += self.values[p] * sx;
            }
        }
    }

    /// The dense copy (`n²` entries: for small models only).
    pub fn to_dense(&self) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(self.n, self.n);
        for (i, j, v) in self.iter() {
            a[(i, j)] += v;
        }
        a
    }

    /// Largest absolute entry.
    pub fn amax(&self) -> f64 {
        self.values.iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    /// Largest `|A - Aᵀ|` entry.
    pub fn asymmetry(&self) -> f64 {
        self.iter()
            .map(|(i, j, v)| (v - self.get(j, i)).abs())
            .fold(0.0, f64::max)
    }

    /// The first non-finite entry, if any.
    pub fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        self.iter().find(|(_, _, v)| !v.is_finite())
    }

    /// `self + Σ s_e w_e w_eᵀ` for sparse weight vectors `w_e`.
    pub fn plus_outer<'a>(
        &self,
        terms: impl IntoIterator<Item = (f64, &'a [(usize, f64)])>,
    ) -> Self {
        let mut t: Vec<(usize, usize, f64)> = self.iter().collect();
        for (s, w) in terms {
            if s == 0.0 {
                continue;
            }
            for &(i, wi) in w {
                for &(j, wj) in w {
                    t.push((i, j, s * wi * wj));
                }
            }
        }
        Self::from_triplets(self.n, &t)
    }

    /// Compressed-column parts: column pointers, row indices, values.
    pub fn parts(&self) -> (&[usize], &[usize], &[f64]) {
        (&self.col_ptr, &self.row_idx, &self.values)
    }
}
