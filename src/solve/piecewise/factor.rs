//! A small dense complex LU with partial pivoting in a reused buffer: the dynamic stiffness
//! `Z_p(lΩ)` of a piece configuration, factored once per harmonic.

use num_complex::Complex64;

/// `P Z = L U` of an n × n complex matrix, row-major, factored in place.
pub(super) struct ComplexLu {
    n: usize,
    a: Vec<Complex64>,
    perm: Vec<usize>,
}

impl ComplexLu {
    pub(super) fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![Complex64::new(0.0, 0.0); n * n],
            perm: vec![0; n],
        }
    }

    /// Fills the matrix with `entry(i, j)` and factors it; returns the smallest pivot relative
    /// to the largest entry (0 for a singular or non-finite matrix).
    pub(super) fn factor(&mut self, entry: impl Fn(usize, usize) -> Complex64) -> f64 {
        let n = self.n;
        let mut scale = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let v = entry(i, j);
                scale = scale.max(v.norm());
                self.a[i * n + j] = v;
            }
        }
        if !scale.is_finite() || scale == 0.0 {
            return 0.0;
        }
        let mut smallest = f64::INFINITY;
        for k in 0..n {
            let p = (k..n)
                .max_by(|&x, &y| {
                    self.a[x * n + k]
                        .norm()
                        .total_cmp(&self.a[y * n + k].norm())
                })
                .unwrap_or(k);
            self.perm[k] = p;
            if p != k {
                for j in 0..n {
                    self.a.swap(k * n + j, p * n + j);
                }
            }
            let pivot = self.a[k * n + k];
            smallest = smallest.min(pivot.norm() / scale);
            if pivot.norm() == 0.0 {
                return 0.0;
            }
            for i in k + 1..n {
                let f = self.a[i * n + k] / pivot;
                self.a[i * n + k] = f;
                for j in k + 1..n {
                    let u = self.a[k * n + j];
                    self.a[i * n + j] -= f * u;
                }
            }
        }
        smallest
    }

    /// Solves `Z x = b` in place.
    pub(super) fn solve(&self, b: &mut [Complex64]) {
        let n = self.n;
        for k in 0..n {
            b.swap(k, self.perm[k]);
        }
        for i in 0..n {
            let row = &self.a[i * n..i * n + i];
            let s = row.iter().zip(&b[..i]).fold(b[i], |s, (l, x)| s - l * x);
            b[i] = s;
        }
        for i in (0..n).rev() {
            let row = &self.a[i * n + i + 1..(i + 1) * n];
            let s = row
                .iter()
                .zip(&b[i + 1..])
                .fold(b[i], |s, (u, x)| s - u * x);
            b[i] = s / self.a[i * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_complex_system_that_needs_pivoting() {
        let c = |re, im| Complex64::new(re, im);
        let z = [[c(0.0, 0.0), c(2.0, 1.0)], [c(1.0, -1.0), c(3.0, 0.5)]];
        let x = [c(0.5, -2.0), c(-1.0, 0.25)];
        let mut b: Vec<Complex64> = (0..2).map(|i| z[i][0] * x[0] + z[i][1] * x[1]).collect();
        let mut lu = ComplexLu::new(2);
        assert!(lu.factor(|i, j| z[i][j]) > 0.1);
        lu.solve(&mut b);
        for (got, want) in b.iter().zip(&x) {
            assert!((got - want).norm() < 1e-15, "{got} against {want}");
        }
        assert_eq!(lu.factor(|_, _| c(1.0, 1.0)), 0.0);
    }
}
