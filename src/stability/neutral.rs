//! Neutral modes: rigid-body motions that no stiffness or element restrains.
//!
//! A vector `r` with `K r = 0`, `D r = 0` and `w_e·r = 0` for every element moves freely: the
//! variational equation has the solutions `(δq, δq̇) = (r, 0)` and `(t r, r)`, so the monodromy
//! matrix has the invariant subspace `V = span{(r, 0), (0, r)}` with the double multiplier 1
//! (`Φ (0, r) = (T r, r)`). A motion held only by damping to ground (`K r = 0`, `w_e·r = 0`,
//! `D r ≠ 0`) keeps the position solution `(r, 0)` alone: `V = span{(r, 0)}`, one multiplier
//! 1; its velocity decays and stays among the multipliers. These multipliers are 1 by
//! construction and say nothing about stability. In an orthonormal basis `[V W]` the
//! monodromy matrix is block upper triangular, and the multipliers that decide stability are
//! those of `Wᵀ Φ W`.

use super::system::Coordinates;
use crate::model::rigid::{columns, free_first, is_static_free};
use nalgebra::DMatrix;

/// The rigid-body modes in some coordinates: orthonormal columns, the free ones first.
pub(crate) struct NeutralModes {
    /// Every motion no stiffness and no element restrains.
    pub(crate) modes: DMatrix<f64>,
    /// How many of the first columns damping does not hold either.
    pub(crate) free: usize,
}

impl NeutralModes {
    /// The multipliers that are 1 by construction: two per free mode, one per held one.
    pub(crate) fn multipliers(&self) -> usize {
        self.modes.ncols() + self.free
    }
}

/// The rigid-body modes in the coordinates `sys`.
pub(crate) fn rigid_body_modes(sys: &Coordinates) -> NeutralModes {
    let modes = match &sys.basis {
        None => in_dofs(sys),
        Some(v) => on_basis(sys, v),
    };
    split_by_damping(sys, modes)
}

/// `S Y` for the eigenvectors `Y` of `Sᵀ D S` (still orthonormal), those free in the model's
/// DOFs ([`is_free`]) first.
fn split_by_damping(sys: &Coordinates, s: DMatrix<f64>) -> NeutralModes {
    if s.ncols() == 0 {
        return NeutralModes { modes: s, free: 0 };
    }
    let h = s.transpose() * &sys.damping * &s;
    let eig = ((&h + h.transpose()) * 0.5).symmetric_eigen();
    let rotated = &s * &eig.eigenvectors;
    let (order, free) = free_first(sys.model, &rotated, |p| sys.lift(p));
    NeutralModes {
        modes: columns(&rotated, &order),
        free,
    }
}

/// The rigid-body modes in the model's DOFs: none unless `K0` is singular by the test the
/// harmonic balance makes of `Z_0` (its smallest LU pivot at most
/// [`SINGULAR_PIVOT`](crate::harmonic::SINGULAR_PIVOT) of its largest entry), so that a
/// motion the solve treated as restrained (a soft ground spring, even one far below the
/// shafts' stiffness) keeps its multipliers among those that decide stability.
fn in_dofs(sys: &Coordinates) -> DMatrix<f64> {
    let n = sys.len();
    if !static_singular(&sys.model.k0().to_dense()) {
        return DMatrix::zeros(n, 0);
    }
    // G = [K/|K|; w_eᵀ/|w_e|]; its null space is the set of motions harmonic 0 cannot fix.
    let mut g = DMatrix::<f64>::zeros(n, n);
    let mut add_rows = |rows: &DMatrix<f64>| {
        let norm = rows.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if norm > 0.0 {
            g += rows.transpose() * rows / (norm * norm);
        }
    };
    add_rows(&sys.stiffness);
    for weights in &sys.weights {
        let mut w = DMatrix::<f64>::zeros(1, n);
        for &(i, wi) in weights {
            w[(0, i)] += wi;
        }
        add_rows(&w);
    }
    let eig = g.symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let free: Vec<usize> = (0..n)
        .filter(|&i| eig.eigenvalues[i].abs() <= 1e-12 * top.max(f64::MIN_POSITIVE))
        .collect();
    let free: Vec<usize> = free
        .into_iter()
        .filter(|&i| is_static_free(sys.model, eig.eigenvectors.column(i).as_slice()))
        .collect();
    let mut r = DMatrix::zeros(n, free.len());
    for (c, &i) in free.iter().enumerate() {
        r.set_column(c, &eig.eigenvectors.column(i));
    }
    r
}

/// `true` if `K0` is singular as `Z_0` is judged: its smallest LU pivot at most
/// `SINGULAR_PIVOT` times its largest entry.
fn static_singular(k0: &DMatrix<f64>) -> bool {
    let scale = k0.amax();
    if scale == 0.0 {
        return true;
    }
    let lu = k0.clone().lu();
    let u = lu.u();
    let smallest = (0..k0.nrows()).fold(f64::INFINITY, |m, i| m.min(u[(i, i)].abs()));
    smallest <= crate::harmonic::SINGULAR_PIVOT * scale
}

/// The rigid-body modes of the model inside the span of the basis `V`, by the same test as in
/// the model's DOFs and independent of the basis's scaling: the null space of the pencil
/// `(Vᵀ G V, VᵀV)`, whose eigenvalues are the Rayleigh quotients `xᵀGx / xᵀx` of
/// `x = V p` with `G` built in the model's DOFs. Orthonormal in the reduced coordinates.
fn on_basis(sys: &Coordinates, v: &DMatrix<f64>) -> DMatrix<f64> {
    let model = sys.model;
    let r = v.ncols();
    let mut g = DMatrix::<f64>::zeros(r, r);
    let mut add_rows = |rows: &DMatrix<f64>, norm: f64| {
        if norm > 0.0 {
            g += rows.transpose() * rows / (norm * norm);
        }
    };
    let k = model.structural_stiffness();
    add_rows(&super::system::sparse_times(k, v), k.amax());
    for e in model.elements() {
        let w = DMatrix::from_fn(1, r, |_, j| {
            e.weights().iter().map(|&(i, wi)| wi * v[(i, j)]).sum()
        });
        let norm = e
            .weights()
            .iter()
            .fold(0.0_f64, |m, &(_, w)| m.max(w.abs()));
        add_rows(&w, norm);
    }
    let Some(chol) = (v.transpose() * v).cholesky() else {
        return DMatrix::zeros(r, 0);
    };
    let Some(l_inv) = chol.l().try_inverse() else {
        return DMatrix::zeros(r, 0);
    };
    let a = &l_inv * g * l_inv.transpose();
    let eig = ((&a + a.transpose()) * 0.5).symmetric_eigen();
    let top = eig.eigenvalues.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let free: Vec<usize> = (0..r)
        .filter(|&i| eig.eigenvalues[i].abs() <= 1e-12 * top.max(f64::MIN_POSITIVE))
        .collect();
    if free.is_empty() {
        return DMatrix::zeros(r, 0);
    }
    let columns: Vec<_> = free
        .iter()
        .map(|&i| l_inv.transpose() * eig.eigenvectors.column(i))
        .filter(|y| is_static_free(model, (v * y).as_slice()))
        .collect();
    if columns.is_empty() {
        return DMatrix::zeros(r, 0);
    }
    DMatrix::from_columns(&columns).qr().q()
}

/// An orthonormal basis of the orthogonal complement of the columns of `v` (orthonormal) in
/// `R^m`.
pub(crate) fn complement(v: &DMatrix<f64>, m: usize) -> DMatrix<f64> {
    if v.ncols() == 0 {
        return DMatrix::identity(m, m);
    }
    let p = DMatrix::<f64>::identity(m, m) - v * v.transpose();
    let eig = p.symmetric_eigen();
    let keep: Vec<usize> = (0..m).filter(|&i| eig.eigenvalues[i] > 0.5).collect();
    let mut w = DMatrix::zeros(m, keep.len());
    for (c, &i) in keep.iter().enumerate() {
        w.set_column(c, &eig.eigenvectors.column(i));
    }
    w
}

/// The state-space bases for rigid-body modes `r` (n × p, the first `f` free):
/// `(positions, all)` with `positions = [(r, 0)]` and `all = [(r, 0), (0, r_free)]`, both
/// orthonormal in `R^{2n}`: `all` spans the invariant subspace of the multipliers 1.
pub(crate) fn state_bases(neutral: &NeutralModes) -> (DMatrix<f64>, DMatrix<f64>) {
    let r = &neutral.modes;
    let (n, p) = r.shape();
    let mut pos = DMatrix::zeros(2 * n, p);
    let mut all = DMatrix::zeros(2 * n, p + neutral.free);
    for c in 0..p {
        for i in 0..n {
            pos[(i, c)] = r[(i, c)];
            all[(i, c)] = r[(i, c)];
            if c < neutral.free {
                all[(n + i, p + c)] = r[(i, c)];
            }
        }
    }
    (pos, all)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::LinearSpring;
    use crate::model::rigid::is_free;
    use crate::model::Model;

    /// A chain of 2000 stiff shaft elements (1e9 N m/rad) held by one soft ground spring
    /// (500 N m/rad): its near-rigid mode is restrained (the squared test of `G` cannot tell),
    /// the same chain without the spring moves freely.
    #[test]
    fn a_soft_ground_spring_restrains_a_long_stiff_chain() {
        let n = 2000;
        let chain = |ground: f64| {
            let mut t: Vec<(usize, usize, f64)> = Vec::new();
            for i in 0..n - 1 {
                t.extend([
                    (i, i, 1e9),
                    (i + 1, i + 1, 1e9),
                    (i, i + 1, -1e9),
                    (i + 1, i, -1e9),
                ]);
            }
            t.push((0, 0, ground));
            let names: Vec<String> = (0..n).map(|i| format!("x{i}")).collect();
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            Model::builder(&names)
                .mass_diagonal(&vec![1e-3; n])
                .stiffness_triplets(&t)
                .build()
                .unwrap()
        };
        let rigid = vec![1.0 / (n as f64).sqrt(); n];
        assert!(!is_free(&chain(500.0), &rigid));
        assert!(is_free(&chain(0.0), &rigid));
    }

    #[test]
    fn two_inertias_on_a_shaft_have_one_rigid_mode() {
        let model = Model::builder(&["a", "b"])
            .mass_diagonal(&[1.0, 2.0])
            .element(
                "shaft",
                &[("a", 1.0), ("b", -1.0)],
                LinearSpring::new(10.0, 0.1),
            )
            .build()
            .unwrap();
        let neutral = rigid_body_modes(&Coordinates::full(&model));
        assert_eq!((neutral.modes.ncols(), neutral.free), (1, 1));
        let r = neutral.modes;
        assert!((r[(0, 0)] - r[(1, 0)]).abs() < 1e-12);
        let grounded = Model::builder(&["a", "b"])
            .mass_diagonal(&[1.0, 2.0])
            .element(
                "shaft",
                &[("a", 1.0), ("b", -1.0)],
                LinearSpring::new(10.0, 0.1),
            )
            .element("ground", &[("a", 1.0)], LinearSpring::new(1e-9, 0.0))
            .build()
            .unwrap();
        let grounded = rigid_body_modes(&Coordinates::full(&grounded));
        assert_eq!(grounded.modes.ncols(), 0);
        let w = complement(&r, 2);
        assert_eq!(w.ncols(), 1);
        assert!((w.column(0).dot(&r.column(0))).abs() < 1e-12);
    }
}
