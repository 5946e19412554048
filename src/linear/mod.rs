//! The linear part of the harmonic balance, kept apart from the nonlinear one (element
//! coordinates, AFT): the dynamic stiffness `Z_k` of a large model held sparse, and the exact
//! condensation onto the element coordinates through the receptances `G_k = Wᵀ Z_k⁻¹ W`.

pub mod condensation;
pub mod sparse_stiffness;

pub use condensation::Condensation;
pub use sparse_stiffness::{SparseDynamicStiffness, SparsePattern};

/// How [`HarmonicBalance`](crate::HarmonicBalance) holds the unknowns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// All n DOFs per harmonic, dense `Z_k` (the paper's formulation).
    #[default]
    Full,
    /// The m element coordinates per harmonic, exact (sparse `Z_k`, receptances).
    Condensed,
}
