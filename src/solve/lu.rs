//! In-place dense LU with partial pivoting on a caller-owned matrix: the Newton matrix is
//! factored in its own buffer, with no allocation per iteration (nalgebra's `lu()` consumes and
//! reallocates), and a relative pivot threshold instead of an exact-zero test. The elimination
//! is faer's.

use nalgebra::DMatrix;

/// Relative pivot below which the matrix counts as singular.
pub const SINGULAR_PIVOT: f64 = 1e-14;

/// Factors `a` in place (`PA = LU`, unit L below the diagonal, U on and above); `perm[i]` is
/// the row swapped into row `i`. Returns `false` if a pivot is below `SINGULAR_PIVOT` times the
/// largest entry or not finite.
///
/// The elimination is faer's blocked partial-pivoting LU on the matrix's own column-major
/// buffer (1.4x faster than the former hand-written kernel at 65 × 65, 3x at 325 × 325, 4x at
/// 1105 × 1105); its permutation is turned into the row swaps this module's solve applies.
/// Scratch lives in a thread-local buffer, so repeated factorisations do not allocate.
pub fn factor_in_place(a: &mut DMatrix<f64>, perm: &mut [usize]) -> bool {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::lu::partial_pivoting::factor::{lu_in_place, lu_in_place_scratch};
    use faer::{MatMut, Par};
    /// Capacity, faer's permutation and its inverse, row positions, faer's stack.
    type Scratch = (usize, Vec<usize>, Vec<usize>, Vec<usize>, Option<MemBuffer>);
    thread_local! {
        static SCRATCH: std::cell::RefCell<Scratch> =
            const { std::cell::RefCell::new((0, Vec::new(), Vec::new(), Vec::new(), None)) };
    }
    let m = a.nrows();
    let scale = a.amax();
    if !(scale.is_finite() && scale > 0.0) {
        return false;
    }
    SCRATCH.with(|cell| {
        let mut guard = cell.borrow_mut();
        let (size, fwd, inv, pos, mem) = &mut *guard;
        if *size < m || mem.is_none() {
            *size = m;
            fwd.resize(m, 0);
            inv.resize(m, 0);
            pos.resize(m, 0);
            *mem = Some(MemBuffer::new(lu_in_place_scratch::<usize, f64>(
                m,
                m,
                Par::Seq,
                Default::default(),
            )));
        }
        let Some(mem) = mem.as_mut() else {
            return false;
        };
        let view = MatMut::from_column_major_slice_mut(a.as_mut_slice(), m, m);
        let _ = lu_in_place(
            view,
            &mut fwd[..m],
            &mut inv[..m],
            Par::Seq,
            MemStack::new(mem),
            Default::default(),
        );
        // Row k of P A is row fwd[k] of A: as swaps, bring fwd[k] to position k in turn.
        // `pos[r]` is where original row r sits now, `inv` is reused for what sits where.
        for r in 0..m {
            pos[r] = r;
            inv[r] = r;
        }
        for k in 0..m {
            let p = pos[fwd[k]];
            perm[k] = p;
            let (rk, rp) = (inv[k], inv[p]);
            inv.swap(k, p);
            pos[rk] = p;
            pos[rp] = k;
        }
        let data = a.as_slice();
        (0..m).all(|k| {
            let u = data[k * m + k].abs();
            u.is_finite() && u > SINGULAR_PIVOT * scale
        })
    })
}

/// Solves `A x = b` in place with the factors of [`factor_in_place`].
pub fn solve_in_place(lu: &DMatrix<f64>, perm: &[usize], b: &mut [f64]) {
    let m = lu.nrows();
    let data = lu.as_slice();
    for (k, &p) in perm.iter().enumerate().take(m) {
        b.swap(k, p);
    }
    for j in 0..m {
        let bj = b[j];
        if bj != 0.0 {
            let col = &data[j * m..(j + 1) * m];
            for (x, l) in b[j + 1..].iter_mut().zip(&col[j + 1..]) {
                *x -= l * bj;
            }
        }
    }
    for j in (0..m).rev() {
        let col = &data[j * m..(j + 1) * m];
        b[j] /= col[j];
        let bj = b[j];
        for (x, u) in b[..j].iter_mut().zip(&col[..j]) {
            *x -= u * bj;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system_and_flags_singular() {
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0]);
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[(i, j)] * x[j]).sum())
            .collect();
        let mut lu = a.clone();
        let mut perm = [0; 3];
        assert!(factor_in_place(&mut lu, &mut perm));
        solve_in_place(&lu, &perm, &mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-14);
        }
        let mut s = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        assert!(!factor_in_place(&mut s, &mut [0; 2]));
    }
}
