//! Rigid-body modes of a free-free model and the static problem in their complement.
//!
//! A free-free drivetrain (driven by a torque, loaded by a torque, no spring to ground) has
//! rigid-body modes `r`: `K r = 0` and `w_e·r = 0` for every element (for gear stages, the
//! rigid rotation compatible with the ratios). Then `K0 r = 0` and the static harmonic
//! `Z_0 = K0` is singular. Harmonics `k >= 1` keep their mass and are regular. Damping does
//! not enter `Z_0`: a motion that only damping to ground holds (a propeller damper, dampers
//! at the crank throws, modal damping whose rigid-mode rounding is not zero) leaves `Z_0` as
//! singular as a free one, and harmonic 0 is solved in the complement of both kinds. They
//! differ in their dynamics: a free mode (`D r = 0` too) drifts at any constant speed, two
//! multipliers 1; one held by damping comes to rest, one multiplier 1
//! ([`RigidModes::free`], [`RigidModes::held`]).
//!
//! **Balance.** `K0 q_0 = f_0` has a solution only if `Rᵀ f_0 = 0`: the mean loads must do no
//! work on a rigid rotation, else the drivetrain accelerates and there is no periodic
//! solution. The elements' forces satisfy it by themselves (`w_e·r = 0`), so only the external
//! mean load is checked ([`RigidModes::check_balance`]).
//!
//! **Normalisation.** With `R` M-orthonormal (`Rᵀ M R = I`), the static solution is fixed by
//! `Rᵀ M q_0 = 0`: the mass-weighted mean rigid angle is zero. It is the unique solution of
//!
//! `(K0 + s M R Rᵀ M) q_0 = f_0`, `s > 0`,
//!
//! (write `q_0 = q_c + R a` with `Rᵀ M q_c = 0`; `Rᵀ` of the equation gives `s a = Rᵀ f_0 = 0`),
//! a symmetric, regular matrix that replaces `Z_0` in the full formulation
//! ([`RigidModes::augmentation`]), so fixed point, Newton, Anderson and continuation see a
//! regular problem whose solutions are those of the free model.
//!
//! **Finding R** scale-independently: subspace iteration `X ← (K0 + σM)⁻¹ M X` with a tiny
//! shift `σ = 10⁻¹⁰ ‖K0‖/‖M‖` amplifies rigid components by `1/σ` against `1/(λ + σ)` for the
//! elastic modes; a Rayleigh–Ritz step separates them, and a candidate is kept only if nothing
//! restrains it (`is_free`, measured on `K`, `D` and the weights themselves).

use super::Model;
use crate::error::{Error, Result};
use nalgebra::DMatrix;

/// Relative shift `σ / (‖K0‖/‖M‖)` of the factorisation `K0 + σM` used to find `R` (and, in the
/// condensed formulation, to solve in the complement).
pub const SHIFT: f64 = 1e-10;

/// Largest relative net torque `|rᵀ f_0| / (max|r| Σ_i |f_0,i|)` still taken for rounding.
pub const BALANCE_TOLERANCE: f64 = 1e-8;

/// Largest relative restraint of `x` that still counts as rounding: `‖K x‖∞ / (max|K| ‖x‖∞)`
/// and the same for `D` and every element's `w·x`.
const FREE_TOLERANCE: f64 = 1e-9;

/// The rigid-body modes `R` (n × p, `Rᵀ M R = I`) of a model, with `M R`: the free ones
/// first, then those held only by damping.
#[derive(Debug, Clone)]
pub struct RigidModes {
    modes: DMatrix<f64>,
    mass_modes: DMatrix<f64>,
    /// How many of the first columns are free (`D r = 0`).
    free: usize,
    /// `‖K0‖/‖M‖` (max entries), a squared frequency inside the model's spectrum.
    scale: f64,
}

impl RigidModes {
    /// The shift `σ` of `K0 + σM` for `model`, and the scale `‖K0‖/‖M‖` it is relative to.
    pub fn shift(model: &Model) -> f64 {
        SHIFT * stiffness_scale(model)
    }

    /// The rigid-body modes of `model`, given `solve`: `x ← (K0 + σM)⁻¹ x` with
    /// `σ =` [`RigidModes::shift`]. `None` if there are none.
    pub fn find(model: &Model, solve: impl Fn(&mut [f64])) -> Option<Self> {
        let n = model.n_dofs();
        let mass = model.mass();
        let k0 = model.k0();
        let mut p = n.min(6);
        loop {
            // Deterministic start vectors: a constant and p - 1 scrambled ones.
            let mut x = DMatrix::from_fn(n, p, |i, c| {
                if c == 0 {
                    1.0
                } else {
                    (((i * 7919 + c * 104_729) % 997) as f64 / 997.0) - 0.5
                }
            });
            let mut y = vec![0.0; n];
            for _ in 0..3 {
                for c in 0..p {
                    y.fill(0.0);
                    mass.mul_add(1.0, x.column(c).as_slice(), &mut y);
                    solve(&mut y);
                    x.set_column(c, &nalgebra::DVector::from_column_slice(&y));
                }
                x = x.qr().q();
            }
            // Rayleigh–Ritz on (Xᵀ K0 X, Xᵀ M X).
            let kx = sparse_times(&k0, &x);
            let mx = sparse_times(mass, &x);
            let (kr, mr) = (x.transpose() * kx, x.transpose() * &mx);
            let chol = mr.cholesky()?;
            let l_inv = chol.l().try_inverse()?;
            let a = &l_inv * kr * l_inv.transpose();
            let eig = ((&a + a.transpose()) * 0.5).symmetric_eigen();
            let free: Vec<_> = (0..p)
                .map(|i| &x * (l_inv.transpose() * eig.eigenvectors.column(i)))
                .filter(|v| is_static_free(model, v.as_slice()))
                .collect();
            if free.len() == p && p < n {
                p = (2 * p).min(n);
                continue;
            }
            if free.is_empty() {
                return None;
            }
            return Some(Self::from_columns(model, &free));
        }
    }

    /// `R` from free vectors: M-orthonormalised by Gram–Schmidt (twice).
    fn from_columns(model: &Model, free: &[nalgebra::DVector<f64>]) -> Self {
        let n = model.n_dofs();
        let mut cols: Vec<nalgebra::DVector<f64>> = Vec::new();
        let mut mcols: Vec<nalgebra::DVector<f64>> = Vec::new();
        let m_times = |v: &nalgebra::DVector<f64>| {
            let mut y = vec![0.0; n];
            model.mass().mul_add(1.0, v.as_slice(), &mut y);
            nalgebra::DVector::from_vec(y)
        };
        for v in free {
            let mut v = v.clone();
            for _ in 0..2 {
                for (c, mc) in cols.iter().zip(&mcols) {
                    v -= c * mc.dot(&v);
                }
            }
            let mv = m_times(&v);
            let norm = v.dot(&mv).sqrt();
            if norm > 0.0 && norm.is_finite() {
                cols.push(v / norm);
                mcols.push(mv / norm);
            }
        }
        let (modes, mass_modes) = (DMatrix::from_columns(&cols), DMatrix::from_columns(&mcols));
        let (modes, mass_modes, free) = split_by_damping(model, modes, mass_modes);
        Self {
            modes,
            mass_modes,
            free,
            scale: stiffness_scale(model),
        }
    }

    /// The free modes (`D r = 0`: two multipliers 1 each).
    pub fn free(&self) -> usize {
        self.free
    }

    /// The modes held only by damping (`D r ≠ 0`: one multiplier 1 each, the position).
    pub fn held(&self) -> usize {
        self.len() - self.free
    }

    /// Number of rigid-body modes p.
    pub fn len(&self) -> usize {
        self.modes.ncols()
    }

    /// `true` without modes (never for a found set).
    pub fn is_empty(&self) -> bool {
        self.modes.ncols() == 0
    }

    /// `R` (n × p), `Rᵀ M R = I`.
    pub fn modes(&self) -> &DMatrix<f64> {
        &self.modes
    }

    /// `M R` (n × p).
    pub fn mass_modes(&self) -> &DMatrix<f64> {
        &self.mass_modes
    }

    /// `s M R Rᵀ M` with `s = ‖K0‖/‖M‖`: added to `K0` it makes the static harmonic regular
    /// and fixes `Rᵀ M q_0 = 0` (see the module docs).
    pub fn augmentation(&self) -> DMatrix<f64> {
        &self.mass_modes * self.mass_modes.transpose() * self.scale
    }

    /// `x ← x - M R (Rᵀ x)`: removes the part of a load that acts on the rigid-body modes.
    pub fn project_load<T>(&self, x: &mut [T])
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
        T: std::ops::SubAssign + Default,
    {
        self.project(x, &self.modes, &self.mass_modes);
    }

    /// `q ← q - R (Rᵀ M q)`: the M-orthogonal projection onto the complement.
    pub fn project_motion<T>(&self, q: &mut [T])
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
        T: std::ops::SubAssign + Default,
    {
        self.project(q, &self.mass_modes, &self.modes);
    }

    /// `x ← x - Σ_c along_c (measure_cᵀ x)`: the oblique projection both of the above are.
    fn project<T>(&self, x: &mut [T], measure: &DMatrix<f64>, along: &DMatrix<f64>)
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
        T: std::ops::SubAssign + Default,
    {
        for c in 0..self.len() {
            let a = measure
                .column(c)
                .iter()
                .zip(x.iter())
                .fold(T::default(), |acc, (&r, &v)| acc + v * r);
            for (xi, &m) in x.iter_mut().zip(along.column(c).iter()) {
                *xi -= a * m;
            }
        }
    }

    /// Checks `Rᵀ f_0 = 0` for the mean load `f0` (length n): an
    /// [`Error::UnbalancedStaticLoad`] naming the net torque (referred to the DOF that moves
    /// most in the mode, which turns by 1 rad) and the loaded DOFs otherwise.
    pub fn check_balance(&self, model: &Model, f0: &[f64]) -> Result<()> {
        for c in 0..self.len() {
            let r = self.modes.column(c);
            // The first DOF that moves most (to rounding: equal entries pick the first).
            let top = r.amax();
            let reference = r
                .iter()
                .position(|v| v.abs() >= (1.0 - 1e-9) * top)
                .unwrap_or(0);
            let sign = r[reference].signum();
            let net: f64 = r.iter().zip(f0).map(|(ri, fi)| ri * fi).sum::<f64>() * sign / top;
            // Against the whole mean load: a mode that carries none of it (another sub-chain's)
            // has a net torque of rounding only, not comparable with its own products.
            let gross: f64 = f0.iter().map(|fi| fi.abs()).sum();
            if net.abs() > BALANCE_TOLERANCE * gross {
                let names = model.dof_names();
                let loaded: Vec<String> = (0..f0.len())
                    .filter(|&i| f0[i] != 0.0 && r[i] != 0.0)
                    .map(|i| format!("`{}` {:+} N m", names[i], f0[i]))
                    .collect();
                return Err(Error::UnbalancedStaticLoad {
                    net,
                    reference: names[reference].clone(),
                    loaded: loaded.join(", "),
                });
            }
        }
        Ok(())
    }
}

/// `‖K0‖/‖M‖` by largest entries (1 if either is zero).
fn stiffness_scale(model: &Model) -> f64 {
    let (k, m) = (model.k0().amax(), model.mass().amax());
    if k > 0.0 && m > 0.0 {
        k / m
    } else {
        1.0
    }
}

/// `A V` for a sparse `A` and dense `V`.
fn sparse_times(a: &super::SparseMatrix, v: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(v.nrows(), v.ncols());
    for c in 0..v.ncols() {
        let mut y = vec![0.0; v.nrows()];
        a.mul_add(1.0, v.column(c).as_slice(), &mut y);
        out.set_column(c, &nalgebra::DVector::from_vec(y));
    }
    out
}

/// `R Y`, `M R Y` with `Y` the eigenvectors of `Rᵀ D R` (orthogonal: still M-orthonormal),
/// the free ones ([`is_free`]) first, and their count.
fn split_by_damping(
    model: &Model,
    modes: DMatrix<f64>,
    mass_modes: DMatrix<f64>,
) -> (DMatrix<f64>, DMatrix<f64>, usize) {
    let dr = sparse_times(model.structural_damping(), &modes);
    let h = modes.transpose() * dr;
    let eig = ((&h + h.transpose()) * 0.5).symmetric_eigen();
    let (rotated, mass_rotated) = (&modes * &eig.eigenvectors, &mass_modes * &eig.eigenvectors);
    let (order, free) = free_first(model, &rotated, |x| x.to_vec());
    (
        columns(&rotated, &order),
        columns(&mass_rotated, &order),
        free,
    )
}

/// The column order of `modes` with the free ones first ([`is_free`] of each column lifted to
/// the model's DOFs by `lift`), and how many are free.
pub(crate) fn free_first(
    model: &Model,
    modes: &DMatrix<f64>,
    lift: impl Fn(&[f64]) -> Vec<f64>,
) -> (Vec<usize>, usize) {
    let (free, held): (Vec<usize>, Vec<usize>) =
        (0..modes.ncols()).partition(|&c| is_free(model, &lift(modes.column(c).as_slice())));
    let count = free.len();
    (free.into_iter().chain(held).collect(), count)
}

/// The columns `order` of `a`, in that order.
pub(crate) fn columns(a: &DMatrix<f64>, order: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(a.nrows(), order.len(), |i, c| a[(i, order[c])])
}

/// `true` if `a x` is rounding against `a`'s largest entry and `x`'s (`scale`).
fn leaves_alone(a: &super::SparseMatrix, x: &[f64], scale: f64) -> bool {
    let top = a.amax();
    if top == 0.0 {
        return true;
    }
    let mut y = vec![0.0; x.len()];
    a.mul_add(1.0, x, &mut y);
    y.iter().all(|v| v.abs() <= FREE_TOLERANCE * top * scale)
}

/// `true` if nothing restrains the motion `x` beyond rounding, measured on the matrices
/// themselves (`K`, `D`, every element's weights). Unsquared, so a soft ground spring on a
/// long stiff chain (500 N m/rad against 1e9 N m/rad shaft elements) is told apart from a
/// rigid-body mode (5e-7 against 1e-15).
pub(crate) fn is_free(model: &Model, x: &[f64]) -> bool {
    let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    is_static_free(model, x) && leaves_alone(model.structural_damping(), x, scale)
}

/// `true` if no stiffness and no element restrains the motion `x` beyond rounding (damping
/// may): a motion harmonic 0 cannot fix, as [`is_free`] without `D`.
pub(crate) fn is_static_free(model: &Model, x: &[f64]) -> bool {
    let scale = x.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return false;
    }
    if !leaves_alone(model.structural_stiffness(), x, scale) {
        return false;
    }
    model.elements().iter().all(|e| {
        let top = e
            .weights()
            .iter()
            .fold(0.0_f64, |m, &(_, w)| m.max(w.abs()));
        e.gather(x).abs() <= FREE_TOLERANCE * top * scale
    })
}

/// The rigid-body modes of a model small enough for dense matrices, by a dense LU of
/// `K0 + σM`; `None` if there are none (or `K0 + σM` is singular: a massless free DOF).
pub fn find_dense(model: &Model, dense: &super::DenseMatrices) -> Option<RigidModes> {
    let sigma = RigidModes::shift(model);
    let lu = (&dense.k0 + &dense.mass * sigma).lu();
    if !lu.is_invertible() {
        return None;
    }
    RigidModes::find(model, |x| {
        let mut v = nalgebra::DVectorViewMut::from_slice(x, model.n_dofs());
        lu.solve_mut(&mut v);
    })
}
