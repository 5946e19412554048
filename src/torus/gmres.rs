//! Restarted GMRES (Saad & Schultz 1986) with right preconditioning, on complex vectors taken
//! as real ones (`⟨a, b⟩ = Re Σ conj(a_i) b_i`): the torus Jacobian is real-linear (it
//! couples `U` and `conj U` through the real samples), not complex-linear.

use num_complex::Complex64;

/// The outcome of one [`gmres`] call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct GmresOutcome {
    /// Matrix-vector products.
    pub iterations: usize,
    /// `‖b - A x‖ / ‖b‖` reached (the recursive estimate).
    pub relative_residual: f64,
}

fn dot(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.re * y.re + x.im * y.im)
        .sum()
}

fn norm(a: &[Complex64]) -> f64 {
    dot(a, a).sqrt()
}

/// Solves `A x = b` to `‖b - A x‖ <= tol ‖b‖` or `max_iterations` products, restarting every
/// `restart`; `x` starts at zero. `apply(v, out)`: `out ← A v`; `precondition(v)`:
/// `v ← P⁻¹ v`.
pub(super) fn gmres(
    mut apply: impl FnMut(&[Complex64], &mut [Complex64]),
    mut precondition: impl FnMut(&mut [Complex64]),
    b: &[Complex64],
    x: &mut [Complex64],
    tol: f64,
    restart: usize,
    max_iterations: usize,
) -> GmresOutcome {
    let n = b.len();
    x.fill(Complex64::default());
    let beta0 = norm(b);
    if beta0 == 0.0 || n == 0 {
        return GmresOutcome {
            iterations: 0,
            relative_residual: 0.0,
        };
    }
    let restart = restart.max(1);
    let mut basis: Vec<Vec<Complex64>> = vec![vec![Complex64::default(); n]; restart + 1];
    let mut h = vec![vec![0.0; restart]; restart + 1];
    let (mut cs, mut sn, mut g) = (
        vec![0.0; restart],
        vec![0.0; restart],
        vec![0.0; restart + 1],
    );
    let mut z = vec![Complex64::default(); n];
    let mut w = vec![Complex64::default(); n];
    let mut total = 0;
    let mut residual;
    loop {
        // r = b - A x.
        apply(x, &mut w);
        for ((r, bi), wi) in basis[0].iter_mut().zip(b).zip(&w) {
            *r = bi - wi;
        }
        let beta = norm(&basis[0]);
        residual = beta / beta0;
        if residual <= tol || total >= max_iterations {
            break;
        }
        basis[0].iter_mut().for_each(|v| *v /= beta);
        g.fill(0.0);
        g[0] = beta;
        let mut k_used = 0;
        for k in 0..restart {
            z.copy_from_slice(&basis[k]);
            precondition(&mut z);
            apply(&z, &mut w);
            total += 1;
            for i in 0..=k {
                let hik = dot(&basis[i], &w);
                h[i][k] = hik;
                for (wv, vv) in w.iter_mut().zip(&basis[i]) {
                    *wv -= vv * hik;
                }
            }
            let hk1 = norm(&w);
            h[k + 1][k] = hk1;
            if hk1 > 0.0 {
                for (v, wv) in basis[k + 1].iter_mut().zip(&w) {
                    *v = wv / hk1;
                }
            }
            for i in 0..k {
                let t = cs[i] * h[i][k] + sn[i] * h[i + 1][k];
                h[i + 1][k] = -sn[i] * h[i][k] + cs[i] * h[i + 1][k];
                h[i][k] = t;
            }
            let r = h[k][k].hypot(h[k + 1][k]);
            (cs[k], sn[k]) = if r > 0.0 {
                (h[k][k] / r, h[k + 1][k] / r)
            } else {
                (1.0, 0.0)
            };
            h[k][k] = r;
            h[k + 1][k] = 0.0;
            g[k + 1] = -sn[k] * g[k];
            g[k] *= cs[k];
            k_used = k + 1;
            residual = g[k + 1].abs() / beta0;
            if residual <= tol || total >= max_iterations || hk1 == 0.0 {
                break;
            }
        }
        // y from the triangular system, then x += P⁻¹ V y.
        let mut y = vec![0.0; k_used];
        for i in (0..k_used).rev() {
            let s: f64 = (i + 1..k_used).map(|j| h[i][j] * y[j]).sum();
            y[i] = if h[i][i] != 0.0 {
                (g[i] - s) / h[i][i]
            } else {
                0.0
            };
        }
        z.fill(Complex64::default());
        for (yi, v) in y.iter().zip(&basis) {
            for (zv, vv) in z.iter_mut().zip(v) {
                *zv += vv * *yi;
            }
        }
        precondition(&mut z);
        for (xi, zi) in x.iter_mut().zip(&z) {
            *xi += zi;
        }
        if residual <= tol || total >= max_iterations {
            break;
        }
    }
    GmresOutcome {
        iterations: total,
        relative_residual: residual,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A real-linear (not complex-linear) map `x ↦ A x + B conj(x)` is solved exactly.
    #[test]
    fn solves_a_real_linear_system() {
        let c = Complex64::new;
        let a = [[c(4.0, 1.0), c(0.5, 0.0)], [c(-0.3, 0.2), c(3.0, -1.0)]];
        let bm = [[c(0.2, 0.1), c(0.0, 0.3)], [c(0.1, 0.0), c(-0.4, 0.2)]];
        let map = |v: &[Complex64], out: &mut [Complex64]| {
            for i in 0..2 {
                out[i] = (0..2)
                    .map(|j| a[i][j] * v[j] + bm[i][j] * v[j].conj())
                    .sum();
            }
        };
        let want = [c(1.0, -2.0), c(0.5, 3.0)];
        let mut b = [Complex64::default(); 2];
        map(&want, &mut b);
        let mut x = [Complex64::default(); 2];
        let out = gmres(map, |_| {}, &b, &mut x, 1e-14, 10, 50);
        assert!(out.relative_residual <= 1e-14, "{out:?}");
        for (x, w) in x.iter().zip(&want) {
            assert!((x - w).norm() < 1e-12, "{x} vs {w}");
        }
        // In R^4 GMRES needs at most 4 products.
        assert!(out.iterations <= 4, "{out:?}");
    }
}
