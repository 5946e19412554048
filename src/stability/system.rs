//! The coordinates the monodromy matrix is integrated in: the model's DOFs, or a reduced basis.
//!
//! With a basis `V` (n × r, `q ≈ V p`) the Galerkin projection of
//! `M q̈ + D q̇ + K q + Σ_e w_e f_e(θ, w_e·q, w_e·q̇) = f(t)` is
//!
//! `M_r p̈ + D_r ṗ + K_r p + Σ_e w̃_e f_e(θ, w̃_e·p, w̃_e·ṗ) = Vᵀ f(t)`,
//! `M_r = VᵀMV`, `D_r = VᵀDV`, `K_r = VᵀKV`, `w̃_e = Vᵀ w_e`,
//!
//! with the model's own force laws (`u_e = w_e·V p = w̃_e·p`). For the model's DOFs (`V = I`)
//! these are the model's matrices and weights; for a square invertible `V` the projection is a
//! similarity transform of the state space and keeps every Floquet multiplier.

use crate::model::Model;
use nalgebra::{DMatrix, DVector};

/// Dense matrices, element weights and load directions in the integration coordinates.
pub(crate) struct Coordinates<'m> {
    pub(crate) model: &'m Model,
    /// `M`, `D` and `K` (structural, without elements) in these coordinates.
    pub(crate) mass: DMatrix<f64>,
    pub(crate) damping: DMatrix<f64>,
    pub(crate) stiffness: DMatrix<f64>,
    /// `w̃_e` per element, sparse.
    pub(crate) weights: Vec<Vec<(usize, f64)>>,
    /// `Vᵀ e_l` per load (the direction its DOF's unit force has).
    pub(crate) loads: Vec<Vec<(usize, f64)>>,
    /// `V` (n × r), `None` for the model's own DOFs.
    pub(crate) basis: Option<DMatrix<f64>>,
}

impl<'m> Coordinates<'m> {
    /// The model's own DOFs (dense copies of its matrices: small models only).
    pub(crate) fn full(model: &'m Model) -> Self {
        Self {
            model,
            mass: model.mass().to_dense(),
            damping: model.structural_damping().to_dense(),
            stiffness: model.structural_stiffness().to_dense(),
            weights: model
                .elements()
                .iter()
                .map(|e| e.weights().to_vec())
                .collect(),
            loads: model.loads().iter().map(|l| vec![(l.dof, 1.0)]).collect(),
            basis: None,
        }
    }

    /// The Galerkin projection onto the columns of `v` (n × r).
    pub(crate) fn reduced(model: &'m Model, v: DMatrix<f64>) -> Self {
        let projected = project_structure(model, &v);
        Self::reduced_with(model, v, &projected)
    }

    /// [`Coordinates::reduced`] with the structure's `(VᵀMV, VᵀDV, VᵀKV)` already formed
    /// ([`project_structure`]).
    pub(crate) fn reduced_with(
        model: &'m Model,
        v: DMatrix<f64>,
        (mass, damping, stiffness): &(DMatrix<f64>, DMatrix<f64>, DMatrix<f64>),
    ) -> Self {
        let r = v.ncols();
        let dense_weights = |w: &[(usize, f64)]| -> Vec<(usize, f64)> {
            (0..r)
                .map(|j| (j, w.iter().map(|&(i, wi)| v[(i, j)] * wi).sum()))
                .collect()
        };
        Self {
            model,
            mass: mass.clone(),
            damping: damping.clone(),
            stiffness: stiffness.clone(),
            weights: model
                .elements()
                .iter()
                .map(|e| dense_weights(e.weights()))
                .collect(),
            loads: model
                .loads()
                .iter()
                .map(|l| dense_weights(&[(l.dof, 1.0)]))
                .collect(),
            basis: Some(v),
        }
    }

    /// Number of coordinates.
    pub(crate) fn len(&self) -> usize {
        self.mass.nrows()
    }

    /// `w̃_e · x`.
    #[inline]
    pub(crate) fn gather(&self, e: usize, x: &[f64]) -> f64 {
        self.weights[e].iter().map(|&(i, w)| x[i] * w).sum()
    }

    /// The load `Vᵀ f(θ)` from `(cos θ, sin θ)`, added into `out` (see
    /// [`Model::load_into_phasor`]).
    pub(crate) fn load_into_phasor(&self, omega: f64, cos: f64, sin: f64, out: &mut [f64]) {
        for (l, dir) in self.model.loads().iter().zip(&self.loads) {
            let (mut c, mut s) = (1.0, 0.0);
            for _ in 0..l.order {
                (c, s) = (c * cos - s * sin, s * cos + c * sin);
            }
            let (lc, ls) = l.at(omega);
            let f = lc * c + ls * s;
            for &(i, w) in dir {
                out[i] += f * w;
            }
        }
    }

    /// Coordinates `p` of every column `x` of `xs`: `x` itself, or the M-orthogonal projection
    /// `(VᵀMV)⁻¹ VᵀM x`.
    pub(crate) fn project(&self, xs: &DMatrix<f64>) -> DMatrix<f64> {
        let Some(v) = &self.basis else {
            return xs.clone();
        };
        let rhs = v.tr_mul(&sparse_times(self.model.mass(), xs));
        match self.mass.clone().cholesky() {
            Some(c) => c.solve(&rhs),
            None => rhs,
        }
    }

    /// The model vector `V p` of coordinates `p`.
    pub(crate) fn lift(&self, p: &[f64]) -> Vec<f64> {
        match &self.basis {
            None => p.to_vec(),
            Some(v) => (v * DVector::from_column_slice(p)).as_slice().to_vec(),
        }
    }
}

/// `A V` for a sparse `A` and a dense `V`.
/// `(VᵀMV, VᵀDV, VᵀKV)` of the model's structure (without its elements) on the basis `v`.
pub(crate) fn project_structure(
    model: &Model,
    v: &DMatrix<f64>,
) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let project = |a: &crate::model::SparseMatrix| v.transpose() * sparse_times(a, v);
    (
        project(model.mass()),
        project(model.structural_damping()),
        project(model.structural_stiffness()),
    )
}

pub(crate) fn sparse_times(a: &crate::model::SparseMatrix, v: &DMatrix<f64>) -> DMatrix<f64> {
    let mut out = DMatrix::zeros(v.nrows(), v.ncols());
    for j in 0..v.ncols() {
        a.mul_add(
            1.0,
            v.column(j).as_slice(),
            out.column_mut(j).as_mut_slice(),
        );
    }
    out
}
