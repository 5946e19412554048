//! Exact condensation onto the element coordinates.
//!
//! Every time-varying or nonlinear element acts on one coordinate `u_e = w_e·q`. Collect the
//! distinct coordinates (parallel weight vectors share one) as the columns of `W` (n × m).
//! With `F_rest(Q) = W R(U)` and `U_k = Wᵀ Q_k`, the harmonic balance
//! `Z_k Q_k + W R_k(U) = F_k` is, exactly,
//!
//! `G_k⁻¹ U_k + R_k(U) = G_k⁻¹ Wᵀ Z_k⁻¹ F_k`, with the receptance `G_k = Wᵀ Z_k⁻¹ W` (m × m),
//!
//! a harmonic balance in m unknowns per harmonic whose "dynamic stiffness" is `G_k⁻¹` (the
//! paper's Section 3 observation: the nonlinear problem lives on the few coupling
//! coordinates). The full `Q_k = Z_k⁻¹ (F_k - W R_k(U))` is recovered by one solve per
//! harmonic. `Z_k` is factored by sparse LU ([`SparseDynamicStiffness`]), `m + 1` solves per
//! harmonic build `G_k` and the condensed load.

use super::sparse_stiffness::{SparseDynamicStiffness, SparsePattern};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::HarmonicBasis;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// The element coordinates `W` and the factored full `Z_k`.
#[derive(Debug)]
pub struct Condensation {
    /// Columns of `W`: weights over the full DOFs.
    coordinates: Vec<Vec<(usize, f64)>>,
    /// A name per coordinate (`u(element)`).
    names: Vec<String>,
    z: SparseDynamicStiffness,
    /// `X_k = Z_k⁻¹ [W | F_k]` (n × (m+1), column-major) per harmonic of the last
    /// [`linear_part`](Self::linear_part), kept where every `Z_k` is symmetric and they fit in
    /// [`MAX_KEPT_BYTES`]: [`recover`](Self::recover) and
    /// [`omega_derivative`](Self::omega_derivative) then need no solve.
    solved: Vec<Vec<Complex64>>,
    /// The full load `F` the kept solutions were made with.
    solved_load: Vec<Complex64>,
    /// The kept solutions belong to the current factors.
    solved_valid: bool,
    /// Each harmonic's work space of the multi-column solve, kept between speeds.
    work: Vec<Vec<Complex64>>,
}

/// The most memory the solved columns `Z_k⁻¹ [W | F_k]` may take (beyond it, each recovery
/// and Ω-derivative solves again).
pub const MAX_KEPT_BYTES: usize = 128 << 20;

/// The condensed linear part on one basis: `G_k⁻¹` per harmonic and the condensed load.
#[derive(Debug, Clone)]
pub struct CondensedLinear {
    /// `G_k⁻¹` for `k = 0..=H` (m × m).
    pub stiffness: Vec<DMatrix<Complex64>>,
    /// `G_k⁻¹ Wᵀ Z_k⁻¹ F_k`, harmonic-major (`(H+1) m`).
    pub load: Vec<Complex64>,
}

impl Condensation {
    /// The coordinates of `element_weights` (the active elements' weights, in order) and the
    /// sparse factors of `Z_k` on `basis`. Returns it and, per active element, its
    /// coordinate and the factor `s` with `w_e = s · W[:, c]`.
    pub fn new(
        model: &Model,
        basis: &HarmonicBasis,
        element_weights: &[(&str, &[(usize, f64)])],
    ) -> Result<(Self, Vec<(usize, f64)>)> {
        let mut coordinates: Vec<Vec<(usize, f64)>> = Vec::new();
        let mut names = Vec::new();
        let mut map = Vec::with_capacity(element_weights.len());
        for (name, w) in element_weights {
            let found = coordinates
                .iter()
                .enumerate()
                .find_map(|(c, v)| parallel(w, v).map(|s| (c, s)));
            match found {
                Some(cs) => map.push(cs),
                None => {
                    coordinates.push(w.to_vec());
                    names.push(format!("u({name})"));
                    map.push((coordinates.len() - 1, 1.0));
                }
            }
        }
        let pattern = SparsePattern::with_hysteretic(
            model.mass(),
            &model.d0(),
            &model.k0(),
            model.hysteretic(),
        );
        // Rigid-body modes are looked for on every model: a sparse `L D Lᵀ` of a singular
        // `K0` can pass its backward-error test (a rounding-sized pivot), so a failed
        // factorisation is no signal. One factorisation of `K0 + σM` and a few solves, O(n).
        let shift = crate::model::RigidModes::shift(model);
        let rigid = SparseDynamicStiffness::shifted_static(pattern.clone(), shift)
            .ok()
            .and_then(|shifted| {
                crate::model::RigidModes::find(model, |x| shifted.solve_static_real(x))
            });
        let z = SparseDynamicStiffness::new_free(
            pattern,
            basis,
            rigid.map(|r| (std::sync::Arc::new(r), shift)),
        )?;
        Ok((
            Self {
                coordinates,
                names,
                z,
                solved: Vec::new(),
                solved_load: Vec::new(),
                solved_valid: false,
                work: Vec::new(),
            },
            map,
        ))
    }

    /// Number of coordinates m.
    pub fn len(&self) -> usize {
        self.coordinates.len()
    }

    /// `true` without coordinates (a linear model).
    pub fn is_empty(&self) -> bool {
        self.coordinates.is_empty()
    }

    /// The coordinates' names.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The rigid-body modes of a free-free model (harmonic 0 is solved in their complement).
    pub fn rigid_modes(&self) -> Option<&std::sync::Arc<crate::model::RigidModes>> {
        self.z.rigid_modes()
    }

    /// Factors `Z_k` for another Ω (each harmonic's factor is verified by the next
    /// [`linear_part`](Self::linear_part), which must follow).
    pub fn refactor(&mut self, basis: &HarmonicBasis) -> Result<()> {
        self.solved_valid = false;
        self.z.refactor_unverified(basis)
    }

    /// `G_k⁻¹` and the condensed load for the full load `f` (harmonic-major, `(H+1) n`).
    ///
    /// One multi-column solve per harmonic, `Z_k⁻¹ [W | F_k | b]`: the receptance, the linear
    /// response and the test vector `b` that verifies the factor
    /// ([`SparseDynamicStiffness::verify`]); the harmonics on several threads with
    /// `HBAL_THREADS`.
    pub fn linear_part(&mut self, f: &[Complex64]) -> Result<CondensedLinear> {
        let (n, m) = (self.z.n(), self.len());
        let h = self.z.harmonics();
        let keep = self.z.is_symmetric()
            && (h + 1) * n * (m + 1) * std::mem::size_of::<Complex64>() <= MAX_KEPT_BYTES;
        // The last speed's buffers, filled again (fresh pages cost more than the solves).
        self.solved_valid = false;
        let (mut xs, mut works) = (
            std::mem::take(&mut self.solved),
            std::mem::take(&mut self.work),
        );
        xs.resize_with(h + 1, Vec::new);
        works.resize_with(h + 1, Vec::new);
        let buffers: Vec<_> = xs.into_iter().zip(works).collect();
        let this = &*self;
        let threads = super::parallel::threads(n * (h + 1));
        let solved = super::parallel::map_owned(buffers, threads, |k, (mut x, mut work)| {
            this.solve_harmonic(k, f, &mut x, &mut work);
            let passed = this.z.check(k, &x[(m + 1) * n..]);
            (x, work, passed)
        });
        let mut stiffness = Vec::with_capacity(h + 1);
        let mut load = vec![Complex64::default(); (h + 1) * m];
        for (k, (mut x, mut work, passed)) in solved.into_iter().enumerate() {
            // A factor that failed its test: the pivoting LU, and that harmonic solved again.
            if !passed && !self.z.verify(k, &x[(m + 1) * n..])? {
                self.solve_harmonic(k, f, &mut x, &mut work);
            }
            self.work.push(work);
            let g = DMatrix::from_fn(m, m, |r, c| self.gather(r, &x[c * n..(c + 1) * n]));
            let u_lin: Vec<Complex64> = (0..m)
                .map(|r| self.gather(r, &x[m * n..(m + 1) * n]))
                .collect();
            let inv = g
                .clone()
                .try_inverse()
                .filter(|i| i.iter().all(|v| v.is_finite()));
            let Some(inv) = inv else {
                return Err(Error::Solver {
                    reason: format!(
                        "condensation: the receptance at harmonic {k} is singular: the element coordinates ({}) are linearly dependent; use the full formulation",
                        self.names.join(", ")
                    ),
                });
            };
            for r in 0..m {
                load[k * m + r] = (0..m).map(|c| inv[(r, c)] * u_lin[c]).sum();
            }
            stiffness.push(inv);
            if keep {
                x.truncate((m + 1) * n);
                self.solved.push(x);
            }
        }
        if keep {
            self.solved_load.clear();
            self.solved_load.extend_from_slice(f);
            self.solved_valid = true;
        }
        Ok(CondensedLinear { stiffness, load })
    }

    /// `x ← Z_k⁻¹ [W | F_k | b]` (n × (m+2), column-major), `b` the factor's test vector
    /// (`work` the solve's work space).
    fn solve_harmonic(
        &self,
        k: usize,
        f: &[Complex64],
        x: &mut Vec<Complex64>,
        work: &mut Vec<Complex64>,
    ) {
        let (n, m) = (self.z.n(), self.len());
        x.clear();
        x.resize(n * (m + 2), Complex64::default());
        for (c, w) in self.coordinates.iter().enumerate() {
            for &(i, wi) in w {
                x[c * n + i] = Complex64::new(wi, 0.0);
            }
        }
        x[m * n..(m + 1) * n].copy_from_slice(&f[k * n..(k + 1) * n]);
        for (xi, bi) in x[(m + 1) * n..].iter_mut().zip(self.z.test_vector()) {
            *xi = bi;
        }
        self.z.solve_in_place_with(k, x, m + 2, work);
    }

    /// The kept `Z_k⁻¹ [W | F_k]` of every harmonic, if kept for the full load `f`.
    fn kept(&self, f: &[Complex64]) -> Option<&[Vec<Complex64>]> {
        (self.solved_valid && self.solved.len() == self.z.harmonics() + 1 && self.solved_load == f)
            .then_some(&self.solved[..])
    }

    /// The full harmonics `Q_k = Z_k⁻¹ (F_k - W R_k)` from the full load `f` and the
    /// condensed rest `rest` (`(H+1) m`).
    pub fn recover(&self, f: &[Complex64], rest: &[Complex64]) -> Vec<Complex64> {
        let (n, m) = (self.z.n(), self.len());
        let h = self.z.harmonics();
        if let Some(solved) = self.kept(f) {
            // Q_k = Z_k⁻¹ F_k - Σ_c R_kc Z_k⁻¹ W[:, c].
            let mut q = vec![Complex64::default(); (h + 1) * n];
            for (k, x) in solved.iter().enumerate() {
                let block = &mut q[k * n..(k + 1) * n];
                block.copy_from_slice(&x[m * n..(m + 1) * n]);
                for c in 0..m {
                    let r = rest[k * m + c];
                    for (qi, xi) in block.iter_mut().zip(&x[c * n..(c + 1) * n]) {
                        *qi -= r * xi;
                    }
                }
            }
            return q;
        }
        let mut q = f.to_vec();
        for k in 0..=h {
            let block = &mut q[k * n..(k + 1) * n];
            for (c, w) in self.coordinates.iter().enumerate() {
                for &(i, wi) in w {
                    block[i] -= rest[k * m + c] * wi;
                }
            }
            self.z.solve_in_place(k, block, 1);
        }
        q
    }

    /// The linear part of `∂R/∂Ω` of the condensed residual `R_k = G_k⁻¹ (U_k - U_lin,k) +
    /// R_k(U)` (`U_lin,k = Wᵀ Z_k⁻¹ F_k`), per harmonic into `out` (`(H+1) m`):
    ///
    /// `∂/∂Ω [G_k⁻¹ (U_k - U_lin,k)] = G_k⁻¹ Wᵀ Z_k⁻¹ (dZ_k/dΩ) y_k`,
    /// `y_k = Z_k⁻¹ (F_k + W G_k⁻¹ (U_k - U_lin,k))`,
    ///
    /// from `dG/dΩ = -Wᵀ Z⁻¹ (dZ/dΩ) Z⁻¹ W` and `dZ⁻¹/dΩ = -Z⁻¹ (dZ/dΩ) Z⁻¹` (at a solution
    /// `y_k` is the full `Q_k`). Two sparse solves per harmonic, or none with the kept solutions. `g_inv` holds the `G_k⁻¹`,
    /// `load` the condensed load `G_k⁻¹ U_lin,k`, `f` the full load.
    #[allow(clippy::too_many_arguments)]
    pub fn omega_derivative(
        &self,
        g_inv: &crate::harmonic::DynamicStiffness,
        load: &[Complex64],
        f: &[Complex64],
        u: &[Complex64],
        nu: usize,
        omega: f64,
        out: &mut [Complex64],
    ) {
        let (n, m) = (self.z.n(), self.len());
        let h = self.z.harmonics();
        let mut y = vec![Complex64::default(); n];
        let mut t = vec![Complex64::default(); n];
        let mut a = vec![Complex64::default(); m];
        let kept = self.kept(f);
        for k in 0..=h {
            let gi = g_inv.matrix(k);
            // a = G⁻¹ (U - U_lin) = G⁻¹ U - load.
            for r in 0..m {
                a[r] =
                    (0..m).map(|c| gi[(r, c)] * u[k * m + c]).sum::<Complex64>() - load[k * m + r];
            }
            if let Some(x) = kept.map(|s| &s[k]) {
                // y = Z⁻¹F + Σ_c a_c Z⁻¹W[:, c]; Wᵀ Z⁻¹ t = (Z⁻¹W)ᵀ t (Z symmetric).
                y.copy_from_slice(&x[m * n..(m + 1) * n]);
                for (c, &ac) in a.iter().enumerate() {
                    for (yi, xi) in y.iter_mut().zip(&x[c * n..(c + 1) * n]) {
                        *yi += ac * xi;
                    }
                }
                self.z
                    .apply_omega_derivative(k as f64 / nu as f64, omega, &y, &mut t);
                for (c, ac) in a.iter_mut().enumerate() {
                    *ac = x[c * n..(c + 1) * n]
                        .iter()
                        .zip(&t)
                        .map(|(xi, ti)| xi * ti)
                        .sum();
                }
            } else {
                y.copy_from_slice(&f[k * n..(k + 1) * n]);
                for (c, w) in self.coordinates.iter().enumerate() {
                    for &(i, wi) in w {
                        y[i] += a[c] * wi;
                    }
                }
                self.z.solve_in_place(k, &mut y, 1);
                self.z
                    .apply_omega_derivative(k as f64 / nu as f64, omega, &y, &mut t);
                self.z.solve_in_place(k, &mut t, 1);
                for (r, ar) in a.iter_mut().enumerate() {
                    *ar = self.gather(r, &t);
                }
            }
            for r in 0..m {
                out[k * m + r] = (0..m).map(|c| gi[(r, c)] * a[c]).sum();
            }
        }
    }

    /// `U = Wᵀ Q` per harmonic.
    pub fn project(&self, q: &[Complex64]) -> Vec<Complex64> {
        let (n, m) = (self.z.n(), self.len());
        let h = q.len() / n.max(1);
        let mut u = vec![Complex64::default(); h * m];
        for k in 0..h {
            for r in 0..m {
                u[k * m + r] = self.gather(r, &q[k * n..(k + 1) * n]);
            }
        }
        u
    }

    /// `W[:, r]ᵀ x`.
    fn gather(&self, r: usize, x: &[Complex64]) -> Complex64 {
        self.coordinates[r]
            .iter()
            .fold(Complex64::default(), |acc, &(i, w)| acc + x[i] * w)
    }
}

/// `Some(s)` if `a = s b` (same DOFs, proportional weights to 1e-12), else `None`.
pub(crate) fn parallel(a: &[(usize, f64)], b: &[(usize, f64)]) -> Option<f64> {
    let nz = |v: &[(usize, f64)]| -> Vec<(usize, f64)> {
        let mut v: Vec<_> = v.iter().copied().filter(|(_, w)| *w != 0.0).collect();
        v.sort_by_key(|(i, _)| *i);
        v
    };
    let (a, b) = (nz(a), nz(b));
    if a.len() != b.len() || a.is_empty() {
        return None;
    }
    let s = a[0].1 / b[0].1;
    let scale = a.iter().map(|(_, w)| w.abs()).fold(0.0, f64::max);
    a.iter()
        .zip(&b)
        .all(|((ia, wa), (ib, wb))| ia == ib && (wa - s * wb).abs() <= 1e-12 * scale)
        .then_some(s)
}
