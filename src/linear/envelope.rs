//! Envelope (skyline) `L D Lᵀ` of a complex symmetric matrix in reverse Cuthill–McKee order.
//!
//! `Z_k = -(kΩ)² M + i kΩ D0 + K0` is complex symmetric (`Zᵀ = Z`, not Hermitian). A
//! drivetrain's graph is a tree of chains, which the reverse Cuthill–McKee ordering (George &
//! Liu, "Computer Solution of Large Sparse Positive Definite Systems", 1981, ch. 4) turns into
//! a band a few entries wide; the row-by-row envelope factorisation (ibid., ch. 4.3: fill stays
//! inside each row's envelope) then costs `O(n b²)` with no symbolic overhead. Without pivoting
//! a factorisation can meet a small pivot (an undamped resonance); the caller checks the
//! backward error of a test solve and falls back to a pivoting sparse LU.

use num_complex::Complex64;
use std::collections::VecDeque;

/// The reverse Cuthill–McKee permutation of a symmetric pattern given by adjacency lists:
/// `perm[new] = old`. Every connected component starts from a vertex of least degree.
pub fn reverse_cuthill_mckee(adjacency: &[Vec<usize>]) -> Vec<usize> {
    let n = adjacency.len();
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    let mut by_degree: Vec<usize> = (0..n).collect();
    by_degree.sort_by_key(|&v| adjacency[v].len());
    let mut queue = VecDeque::new();
    let mut next = Vec::new();
    for &root in &by_degree {
        if seen[root] {
            continue;
        }
        seen[root] = true;
        queue.push_back(root);
        while let Some(v) = queue.pop_front() {
            order.push(v);
            next.clear();
            next.extend(adjacency[v].iter().copied().filter(|&w| !seen[w]));
            next.sort_by_key(|&w| adjacency[w].len());
            next.dedup();
            for &w in &next {
                if !seen[w] {
                    seen[w] = true;
                    queue.push_back(w);
                }
            }
        }
    }
    order.reverse();
    order
}

/// The envelope structure of a symmetric pattern in a given order: row `i` (new numbering)
/// stores columns `first[i]..=i`.
#[derive(Debug, Clone)]
pub struct Envelope {
    /// `perm[new] = old`.
    perm: Vec<usize>,
    /// `inverse[old] = new`.
    inverse: Vec<usize>,
    /// First stored column of each row.
    first: Vec<usize>,
    /// Start of each row in the value array (`start[n]` = total).
    start: Vec<usize>,
}

impl Envelope {
    /// The envelope of the symmetric pattern `(row, column)` pairs of an `n × n` matrix in
    /// reverse Cuthill–McKee order.
    pub fn new(n: usize, entries: impl Iterator<Item = (usize, usize)> + Clone) -> Self {
        let mut adjacency = vec![Vec::new(); n];
        for (i, j) in entries.clone() {
            if i != j {
                adjacency[i].push(j);
                adjacency[j].push(i);
            }
        }
        let perm = reverse_cuthill_mckee(&adjacency);
        let mut inverse = vec![0; n];
        for (new, &old) in perm.iter().enumerate() {
            inverse[old] = new;
        }
        let mut first: Vec<usize> = (0..n).collect();
        for (i, j) in entries {
            let (a, b) = (inverse[i], inverse[j]);
            let (hi, lo) = if a >= b { (a, b) } else { (b, a) };
            first[hi] = first[hi].min(lo);
        }
        let mut start = Vec::with_capacity(n + 1);
        start.push(0);
        for (i, f) in first.iter().enumerate() {
            start.push(start[i] + (i - f + 1));
        }
        Self {
            perm,
            inverse,
            first,
            start,
        }
    }

    /// Stored entries (lower triangle with the diagonal).
    pub fn size(&self) -> usize {
        *self.start.last().unwrap_or(&0)
    }

    /// `true` if `(i, j)` (original numbering) lies on or below the diagonal in the new order.
    pub fn is_lower(&self, i: usize, j: usize) -> bool {
        self.inverse[i] >= self.inverse[j]
    }

    /// Position of the lower-triangle entry `(i, j)` (original numbering) in the values.
    pub fn position(&self, i: usize, j: usize) -> usize {
        let (a, b) = (self.inverse[i], self.inverse[j]);
        let (hi, lo) = if a >= b { (a, b) } else { (b, a) };
        self.start[hi] + (lo - self.first[hi])
    }

    /// Factors in place `values` (the lower triangle of a complex symmetric matrix in this
    /// envelope) into `L` (unit, below the diagonal) and `D⁻¹` (on it). `false` if a pivot is
    /// zero or not finite.
    pub fn factor(&self, values: &mut [Complex64]) -> bool {
        let n = self.first.len();
        // d_k kept apart while rows below still need it; the diagonal gets 1/d_k.
        let mut d = vec![Complex64::default(); n];
        for i in 0..n {
            let (fi, si) = (self.first[i], self.start[i]);
            // Row i: l_ij = (a_ij - Σ_k l_ik d_k l_jk) / d_j.
            for j in fi..i {
                let (fj, sj) = (self.first[j], self.start[j]);
                let k0 = fi.max(fj);
                let mut s = values[si + (j - fi)];
                for k in k0..j {
                    s -= values[si + (k - fi)] * d[k] * values[sj + (k - fj)];
                }
                values[si + (j - fi)] = s * values[sj + (j - fj)];
            }
            let mut di = values[si + (i - fi)];
            for k in fi..i {
                let l = values[si + (k - fi)];
                di -= l * l * d[k];
            }
            if !(di.norm_sqr() > 0.0 && di.re.is_finite() && di.im.is_finite()) {
                return false;
            }
            d[i] = di;
            values[si + (i - fi)] = di.inv();
        }
        true
    }

    /// `x ← Z⁻¹ x` for `columns` right-hand sides (column-major `n × columns`) with the
    /// factors in `values`; `work` has `n · columns` entries.
    pub fn solve(
        &self,
        values: &[Complex64],
        x: &mut [Complex64],
        columns: usize,
        work: &mut [Complex64],
    ) {
        let n = self.first.len();
        // work is row-major n × columns: the columns of one row side by side.
        for (new, &old) in self.perm.iter().enumerate() {
            for c in 0..columns {
                work[new * columns + c] = x[c * n + old];
            }
        }
        let work = &mut work[..n * columns];
        // A row of up to 8 columns is held in registers (the condensation solves m + 2
        // columns); the same operations in the same order as the general loop.
        match columns {
            1 => self.substitute::<1>(values, work),
            2 => self.substitute::<2>(values, work),
            3 => self.substitute::<3>(values, work),
            4 => self.substitute::<4>(values, work),
            5 => self.substitute::<5>(values, work),
            6 => self.substitute::<6>(values, work),
            7 => self.substitute::<7>(values, work),
            8 => self.substitute::<8>(values, work),
            _ => self.substitute_any(values, work, columns),
        }
        for (new, &old) in self.perm.iter().enumerate() {
            for c in 0..columns {
                x[c * n + old] = work[new * columns + c];
            }
        }
    }

    /// `L D Lᵀ` substitution on `work` (row-major, `C` columns), each row in an array.
    fn substitute<const C: usize>(&self, values: &[Complex64], work: &mut [Complex64]) {
        let n = self.first.len();
        let row_of = |work: &[Complex64], i: usize| -> [Complex64; C] {
            std::array::from_fn(|c| work[i * C + c])
        };
        // L y = b: row i takes the finished rows k < i of its envelope.
        for i in 0..n {
            let (fi, si) = (self.first[i], self.start[i]);
            let mut row = row_of(work, i);
            for (k, l) in (fi..i).zip(&values[si..si + (i - fi)]) {
                let src = row_of(work, k);
                for c in 0..C {
                    row[c] -= l * src[c];
                }
            }
            work[i * C..(i + 1) * C].copy_from_slice(&row);
        }
        self.scale_by_pivots(values, work, C);
        // Lᵀ x = z, from the last row: row i, final, updates the rows k < i of its envelope.
        for i in (0..n).rev() {
            let (fi, si) = (self.first[i], self.start[i]);
            let row = row_of(work, i);
            for (k, l) in (fi..i).zip(&values[si..si + (i - fi)]) {
                let dst = &mut work[k * C..(k + 1) * C];
                for c in 0..C {
                    dst[c] -= l * row[c];
                }
            }
        }
    }

    /// `D z = y`: every row of `work` (row-major, `columns` wide) times its `D⁻¹`.
    fn scale_by_pivots(&self, values: &[Complex64], work: &mut [Complex64], columns: usize) {
        for (i, row) in work.chunks_exact_mut(columns).enumerate() {
            let inv = values[self.start[i] + (i - self.first[i])];
            for r in row.iter_mut() {
                *r *= inv;
            }
        }
    }

    /// [`Self::substitute`] for any number of columns.
    fn substitute_any(&self, values: &[Complex64], work: &mut [Complex64], columns: usize) {
        let n = self.first.len();
        // L y = b: row i takes the finished rows k < i of its envelope.
        for i in 0..n {
            let (fi, si) = (self.first[i], self.start[i]);
            let (done, rest) = work.split_at_mut(i * columns);
            let row = &mut rest[..columns];
            let coefficients = &values[si..si + (i - fi)];
            for (l, src) in coefficients
                .iter()
                .zip(done[fi * columns..].chunks_exact(columns))
            {
                for (r, v) in row.iter_mut().zip(src) {
                    *r -= l * v;
                }
            }
        }
        self.scale_by_pivots(values, work, columns);
        // Lᵀ x = z, from the last row: row i, final, updates the rows k < i of its envelope.
        for i in (0..n).rev() {
            let (fi, si) = (self.first[i], self.start[i]);
            let (head, rest) = work.split_at_mut(i * columns);
            let row = &rest[..columns];
            let coefficients = &values[si..si + (i - fi)];
            for (l, dst) in coefficients
                .iter()
                .zip(head[fi * columns..].chunks_exact_mut(columns))
            {
                for (d, v) in dst.iter_mut().zip(row) {
                    *d -= l * v;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 5-node tree (a star with a tail) factored and solved against the dense product.
    #[test]
    fn envelope_ldlt_solves_a_complex_symmetric_tree() {
        let n = 5;
        let edges = [(0, 1), (0, 2), (0, 3), (3, 4)];
        let mut a = vec![vec![Complex64::default(); n]; n];
        for (i, row) in a.iter_mut().enumerate() {
            row[i] = Complex64::new(4.0 + i as f64, 0.3 * i as f64);
        }
        for &(i, j) in &edges {
            let v = Complex64::new(-1.0, 0.1 * (i + j) as f64);
            a[i][j] = v;
            a[j][i] = v;
        }
        let entries: Vec<(usize, usize)> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .filter(|&(i, j)| a[i][j] != Complex64::default())
            .collect();
        let env = Envelope::new(n, entries.iter().copied());
        assert!(env.size() <= 2 * n, "envelope {}", env.size());
        let mut values = vec![Complex64::default(); env.size()];
        for &(i, j) in &entries {
            values[env.position(i, j)] = a[i][j];
        }
        assert!(env.factor(&mut values));
        let b: Vec<Complex64> = (0..n)
            .map(|i| Complex64::new(1.0 + i as f64, -0.5))
            .collect();
        let mut x = b.clone();
        let mut work = vec![Complex64::default(); n];
        env.solve(&values, &mut x, 1, &mut work);
        for i in 0..n {
            let ax: Complex64 = (0..n).map(|j| a[i][j] * x[j]).sum();
            assert!((ax - b[i]).norm() < 1e-13, "row {i}: {ax} vs {}", b[i]);
        }
        // Every width of the register-held rows gives the general loop's bits, column by
        // column the one-column solve's answer.
        for columns in 1..=9 {
            let rhs: Vec<Complex64> = (0..n * columns)
                .map(|i| Complex64::new((i % 7) as f64 - 2.5, 0.25 * (i % 3) as f64))
                .collect();
            let mut fast = rhs.clone();
            let mut work = vec![Complex64::default(); n * columns];
            env.solve(&values, &mut fast, columns, &mut work);
            let mut general = rhs.clone();
            for (new, &old) in env.perm.iter().enumerate() {
                for c in 0..columns {
                    work[new * columns + c] = general[c * n + old];
                }
            }
            env.substitute_any(&values, &mut work, columns);
            for (new, &old) in env.perm.iter().enumerate() {
                for c in 0..columns {
                    general[c * n + old] = work[new * columns + c];
                }
            }
            assert_eq!(fast, general, "{columns} columns");
            for c in 0..columns {
                let mut one = rhs[c * n..(c + 1) * n].to_vec();
                env.solve(&values, &mut one, 1, &mut work);
                assert_eq!(one, fast[c * n..(c + 1) * n], "column {c} of {columns}");
            }
        }
    }

    /// A chain numbered badly (0, 9, 1, 8, ...) gets bandwidth 1 back from RCM.
    #[test]
    fn rcm_restores_a_chain() {
        let order = [0usize, 9, 1, 8, 2, 7, 3, 6, 4, 5];
        let mut adjacency = vec![Vec::new(); 10];
        for w in order.windows(2) {
            adjacency[w[0]].push(w[1]);
            adjacency[w[1]].push(w[0]);
        }
        let perm = reverse_cuthill_mckee(&adjacency);
        let mut inverse = [0usize; 10];
        for (new, &old) in perm.iter().enumerate() {
            inverse[old] = new;
        }
        for w in order.windows(2) {
            assert_eq!((inverse[w[0]] as i64 - inverse[w[1]] as i64).abs(), 1);
        }
    }
}
