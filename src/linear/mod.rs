//! The linear part of the harmonic balance, kept apart from the nonlinear one (element
//! coordinates, AFT): the dynamic stiffness `Z_k` of a large model held sparse, and the exact
//! condensation onto the element coordinates through the receptances `G_k = Wᵀ Z_k⁻¹ W`.

pub mod condensation;
pub mod envelope;
pub(crate) mod parallel;
mod sparse_factor;
pub mod sparse_pattern;
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
    /// Condensed where it pays: above [`Model::MAX_DENSE_DOFS`](crate::Model::MAX_DENSE_DOFS)
    /// DOFs, or from 4 DOFs when there are at most half as many time-varying or nonlinear
    /// elements (Newton's dense solve then shrinks by `(n/m)³`, 27 times for 6 DOFs and 2
    /// elements); full otherwise.
    Auto,
}

impl Formulation {
    /// The formulation `self` means for `model` (`Auto` resolved).
    ///
    /// ```
    /// use hbal::{catalog::GearBacklash, Formulation};
    /// let model = GearBacklash::default().model()?;
    /// assert_eq!(Formulation::Auto.resolve(&model), Formulation::Full);
    /// # Ok::<(), hbal::Error>(())
    /// ```
    pub fn resolve(self, model: &crate::Model) -> Formulation {
        match self {
            Formulation::Auto => {
                let n = model.n_dofs();
                let m = model
                    .elements()
                    .iter()
                    .filter(|e| !e.law().is_linear_time_invariant())
                    .count();
                if n > crate::Model::MAX_DENSE_DOFS || (n >= 4 && m >= 1 && 2 * m <= n) {
                    Formulation::Condensed
                } else {
                    Formulation::Full
                }
            }
            f => f,
        }
    }
}

impl std::str::FromStr for Formulation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "full" => Ok(Formulation::Full),
            "condensed" => Ok(Formulation::Condensed),
            "auto" => Ok(Formulation::Auto),
            _ => Err(format!("expected `full`, `condensed` or `auto`, got `{s}`")),
        }
    }
}
