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

/// The Arnoldi basis of one restart cycle with the Hessenberg matrix reduced by Givens
/// rotations as it grows, and the rotated right-hand side `g` (`|g[k]|` is the residual).
struct Arnoldi {
    basis: Vec<Vec<Complex64>>,
    h: Vec<Vec<f64>>,
    rotations: Vec<(f64, f64)>,
    g: Vec<f64>,
}

impl Arnoldi {
    fn new(n: usize, restart: usize) -> Self {
        Self {
            // Grown as the cycle needs it (most directions take a few products, not `restart`).
            basis: vec![vec![Complex64::default(); n]],
            h: vec![vec![0.0; restart]; restart + 1],
            rotations: vec![(1.0, 0.0); restart],
            g: vec![0.0; restart + 1],
        }
    }

    /// Starts a cycle from the residual in `basis[0]` of norm `beta`.
    fn start(&mut self, beta: f64) {
        self.basis[0].iter_mut().for_each(|v| *v /= beta);
        self.g.fill(0.0);
        self.g[0] = beta;
    }

    /// Adds `w = A P⁻¹ v_k` as column k: orthogonalises it (modified Gram–Schmidt), rotates
    /// the column, and returns the new residual norm and whether the space is exhausted.
    fn extend(&mut self, k: usize, w: &mut [Complex64]) -> (f64, bool) {
        for i in 0..=k {
            let hik = dot(&self.basis[i], w);
            self.h[i][k] = hik;
            for (wv, vv) in w.iter_mut().zip(&self.basis[i]) {
                *wv -= vv * hik;
            }
        }
        let hk1 = norm(w);
        self.h[k + 1][k] = hk1;
        if self.basis.len() <= k + 1 {
            self.basis.push(vec![Complex64::default(); w.len()]);
        }
        if hk1 > 0.0 {
            for (v, wv) in self.basis[k + 1].iter_mut().zip(w.iter()) {
                *v = wv / hk1;
            }
        }
        for i in 0..k {
            let (c, s) = self.rotations[i];
            let t = c * self.h[i][k] + s * self.h[i + 1][k];
            self.h[i + 1][k] = -s * self.h[i][k] + c * self.h[i + 1][k];
            self.h[i][k] = t;
        }
        let r = self.h[k][k].hypot(self.h[k + 1][k]);
        let (c, s) = if r > 0.0 {
            (self.h[k][k] / r, self.h[k + 1][k] / r)
        } else {
            (1.0, 0.0)
        };
        self.rotations[k] = (c, s);
        self.h[k][k] = r;
        self.h[k + 1][k] = 0.0;
        self.g[k + 1] = -s * self.g[k];
        self.g[k] *= c;
        (self.g[k + 1].abs(), hk1 == 0.0)
    }

    /// `z ← V y` with `y` from the triangular system of the first `k` columns.
    fn combination(&self, k: usize, z: &mut [Complex64]) {
        let mut y = vec![0.0; k];
        for i in (0..k).rev() {
            let s: f64 = (i + 1..k).map(|j| self.h[i][j] * y[j]).sum();
            y[i] = if self.h[i][i] != 0.0 {
                (self.g[i] - s) / self.h[i][i]
            } else {
                0.0
            };
        }
        z.fill(Complex64::default());
        for (yi, v) in y.iter().zip(&self.basis) {
            for (zv, vv) in z.iter_mut().zip(v) {
                *zv += vv * *yi;
            }
        }
    }
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
    let mut arnoldi = Arnoldi::new(n, restart);
    let (mut z, mut w) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
    let mut total = 0;
    let mut residual;
    loop {
        apply(x, &mut w);
        for ((r, bi), wi) in arnoldi.basis[0].iter_mut().zip(b).zip(&w) {
            *r = bi - wi;
        }
        let beta = norm(&arnoldi.basis[0]);
        residual = beta / beta0;
        if residual <= tol || total >= max_iterations {
            break;
        }
        arnoldi.start(beta);
        let mut used = 0;
        for k in 0..restart {
            z.copy_from_slice(&arnoldi.basis[k]);
            precondition(&mut z);
            apply(&z, &mut w);
            total += 1;
            let (r, exhausted) = arnoldi.extend(k, &mut w);
            used = k + 1;
            residual = r / beta0;
            if residual <= tol || total >= max_iterations || exhausted {
                break;
            }
        }
        // Right preconditioning: x += P⁻¹ V y.
        arnoldi.combination(used, &mut z);
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
