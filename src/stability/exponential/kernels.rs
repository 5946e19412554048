//! The small dense kernels of the exponential flow's inner loops, with AVX2/FMA where the CPU
//! has them (the crate is compiled for the baseline x86-64: SSE2, no FMA).
//!
//! * [`gemv`], [`gemv_sum`]: `y = Σ A_k x_k` or `y += …` for column-major matrices, sixteen
//!   or eight rows at a time held in registers over all columns (the state's sub-steps
//!   `x̃ ← E x̃ + X z` and the Taylor coefficients `Ã x̃⁽ⁱ⁾` of the orbit: 2n = 40 rows);
//! * [`horner`]: `out = Σ_{i<=d} τⁱ Tᵢ` by Horner's rule elementwise over matrices `Tᵢ` (the
//!   short exponential `e^{Ãτ}` from the kept `Ãⁱ/i!`);
//! * [`product`]: `C = A B` by faer's matrix product (the monodromy matrix's factors).
//!
//! With FMA the multiply-adds are fused (one rounding instead of two): results differ from the
//! fallback's in the last bits only.

use nalgebra::DMatrix;

/// `true` where the AVX2/FMA kernels can run.
fn fast() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `y = A x` (`add`: `y += A x`) with `A` column-major, `y.len()` rows and `x.len()` columns.
pub(crate) fn gemv(a: &DMatrix<f64>, x: &[f64], y: &mut [f64], add: bool) {
    gemv_sum(&[(a, x)], y, add);
}

/// `y = Σ A_k x_k` (`add`: `y += Σ A_k x_k`) over the pairs `(A_k, x_k)`, each row's sum in
/// the pairs' and columns' order (so the same bits as one [`gemv`] after another).
pub(crate) fn gemv_sum(terms: &[(&DMatrix<f64>, &[f64])], y: &mut [f64], add: bool) {
    let mut slices = [(&[][..], &[][..]); 4];
    assert!(terms.len() <= slices.len());
    for (s, &(a, x)) in slices.iter_mut().zip(terms) {
        assert!(a.nrows() == y.len() && a.ncols() == x.len());
        *s = (a.as_slice(), x);
    }
    let terms = &slices[..terms.len()];
    #[cfg(target_arch = "x86_64")]
    {
        if fast() {
            // SAFETY: the CPU supports the features the function is compiled for.
            return unsafe { gemv_avx2_fma(terms, y, add) };
        }
    }
    gemv_kernel::<false>(terms, y, add)
}

/// Pairs (column-major matrix, vector) of a [`gemv_sum`].
type Terms<'a> = [(&'a [f64], &'a [f64])];

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn gemv_avx2_fma(terms: &Terms, y: &mut [f64], add: bool) {
    gemv_kernel::<true>(terms, y, add)
}

/// Multiply-add `a b + c`, fused with `FMA` (only where the CPU has it: otherwise `mul_add` is
/// a slow library call).
#[inline(always)]
fn madd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// Rows `r..r + R` of `Σ A_k x_k` (matrices with `m` rows), accumulated onto `init` in
/// registers over every column.
#[inline(always)]
fn rows<const FMA: bool, const R: usize>(
    terms: &Terms,
    m: usize,
    r: usize,
    init: [f64; R],
) -> [f64; R] {
    let mut acc = init;
    for &(a, x) in terms {
        for (col, &xj) in a.chunks_exact(m).zip(x) {
            let c = &col[r..r + R];
            for i in 0..R {
                acc[i] = madd::<FMA>(c[i], xj, acc[i]);
            }
        }
    }
    acc
}

/// Blocks of sixteen rows, then eight, then the last eight rows again (the overlap recomputed
/// to the same bits, from the entries `y` had before) instead of a scalar tail.
#[inline(always)]
fn gemv_kernel<const FMA: bool>(terms: &Terms, y: &mut [f64], add: bool) {
    let m = y.len();
    if m < 8 {
        for (i, yi) in y.iter_mut().enumerate() {
            let mut s = if add { *yi } else { 0.0 };
            for &(a, x) in terms {
                for (col, &xj) in a.chunks_exact(m).zip(x) {
                    s = madd::<FMA>(col[i], xj, s);
                }
            }
            *yi = s;
        }
        return;
    }
    let start = |y: &[f64], r: usize| -> [f64; 8] {
        let mut init = [0.0; 8];
        if add {
            init.copy_from_slice(&y[r..r + 8]);
        }
        init
    };
    let last = start(y, m - 8);
    let mut r = 0;
    while r + 16 <= m {
        let mut init = [0.0; 16];
        if add {
            init.copy_from_slice(&y[r..r + 16]);
        }
        y[r..r + 16].copy_from_slice(&rows::<FMA, 16>(terms, m, r, init));
        r += 16;
    }
    if r + 8 <= m {
        let init = start(y, r);
        y[r..r + 8].copy_from_slice(&rows::<FMA, 8>(terms, m, r, init));
        r += 8;
    }
    if r < m {
        y[m - 8..].copy_from_slice(&rows::<FMA, 8>(terms, m, m - 8, last));
    }
}

/// `out = Σ_{i<=d} τⁱ Tᵢ` for `terms = [T₀, …, T_d]` (same shape as `out`), by Horner's rule:
/// `out = T_d`, then `out ← out τ + Tᵢ` for `i = d-1, …, 0`.
pub(crate) fn horner(terms: &[DMatrix<f64>], tau: f64, out: &mut DMatrix<f64>) {
    let (last, rest) = terms.split_last().expect("a term");
    out.copy_from(last);
    #[cfg(target_arch = "x86_64")]
    {
        if fast() {
            // SAFETY: the CPU supports the features the function is compiled for.
            return unsafe { horner_avx2_fma(rest, tau, out.as_mut_slice()) };
        }
    }
    horner_kernel::<false>(rest, tau, out.as_mut_slice())
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn horner_avx2_fma(terms: &[DMatrix<f64>], tau: f64, out: &mut [f64]) {
    horner_kernel::<true>(terms, tau, out)
}

/// Horner's rule on `out` (holding the last term) with `terms` below it, sixteen entries at a
/// time held in registers over all terms (loads only, one store per entry).
#[inline(always)]
fn horner_kernel<const FMA: bool>(terms: &[DMatrix<f64>], tau: f64, out: &mut [f64]) {
    const R: usize = 16;
    let len = out.len();
    let mut r = 0;
    while r + R <= len {
        let mut acc = [0.0; R];
        acc.copy_from_slice(&out[r..r + R]);
        for term in terms.iter().rev() {
            let t = &term.as_slice()[r..r + R];
            for i in 0..R {
                acc[i] = madd::<FMA>(acc[i], tau, t[i]);
            }
        }
        out[r..r + R].copy_from_slice(&acc);
        r += R;
    }
    for (i, o) in out.iter_mut().enumerate().skip(r) {
        for term in terms.iter().rev() {
            *o = madd::<FMA>(*o, tau, term.as_slice()[i]);
        }
    }
}

/// `out = a b` (faer's kernel: faster than nalgebra's on the 40 × 40 factors of the monodromy
/// matrix).
pub(crate) fn product(a: &DMatrix<f64>, b: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    product_scaled(1.0, a, b, out);
}

/// `out = α a b`.
pub(crate) fn product_scaled(
    alpha: f64,
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    out: &mut DMatrix<f64>,
) {
    use faer::linalg::matmul::matmul;
    use faer::{Accum, MatMut, MatRef, Par};
    let (m, k, n) = (a.nrows(), a.ncols(), b.ncols());
    assert!(b.nrows() == k && out.nrows() == m && out.ncols() == n);
    let a = MatRef::from_column_major_slice(a.as_slice(), m, k);
    let b = MatRef::from_column_major_slice(b.as_slice(), k, n);
    let c = MatMut::from_column_major_slice_mut(out.as_mut_slice(), m, n);
    matmul(c, Accum::Replace, a, b, alpha, Par::Seq);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_kernels_match_nalgebra() {
        for (m, k) in [(40, 40), (34, 5), (7, 3), (17, 17), (8, 2), (26, 4)] {
            let a = DMatrix::from_fn(m, k, |i, j| ((3 * i + 7 * j) as f64).sin());
            let x: Vec<f64> = (0..k).map(|j| (j as f64 * 0.3).cos()).collect();
            let xv = nalgebra::DVector::from_column_slice(&x);
            let mut y = vec![0.5; m];
            gemv(&a, &x, &mut y, false);
            let exact = &a * &xv;
            let err = y.iter().zip(exact.iter()).map(|(p, q)| (p - q).abs());
            assert!(err.fold(0.0, f64::max) < 1e-14);
            gemv(&a, &x, &mut y, true);
            let err = y.iter().zip(exact.iter()).map(|(p, q)| (p - 2.0 * q).abs());
            assert!(err.fold(0.0, f64::max) < 1e-14);
            // Two pairs in one sum: the bits of one product after the other.
            let mut two = vec![0.25; m];
            gemv_sum(&[(&a, &x), (&a, &x)], &mut two, true);
            let mut one = vec![0.25; m];
            gemv(&a, &x, &mut one, true);
            gemv(&a, &x, &mut one, true);
            assert_eq!(two, one);
        }
        let terms: Vec<DMatrix<f64>> = (0..5)
            .map(|i| DMatrix::from_fn(6, 6, |r, c| ((r + 2 * c + i) as f64).cos()))
            .collect();
        let tau = 0.37;
        let mut out = DMatrix::zeros(6, 6);
        horner(&terms, tau, &mut out);
        let exact = terms
            .iter()
            .enumerate()
            .fold(DMatrix::zeros(6, 6), |s, (i, t)| s + t * tau.powi(i as i32));
        assert!((out - exact).amax() < 1e-14);
        let (a, b) = (&terms[1], &terms[2]);
        let mut c = DMatrix::zeros(6, 6);
        product(a, b, &mut c);
        assert!((c - a * b).amax() < 1e-14);
    }
}
