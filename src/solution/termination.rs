//! Why a solve stopped.

/// Why an iteration stopped. Only [`Termination::Converged`] means the tolerance was met; in
/// every case the [`Solution`](super::Solution) holds the last finite iterate.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The relative residual fell below the tolerance.
    Converged,
    /// The iteration limit was reached first.
    MaxIterations,
    /// The residual grew by more than the divergence factor over its best value: the fixed-point
    /// map is not a contraction here (raise γ, or use an accelerated solver).
    Diverged,
    /// A force or linear solve produced NaN or infinity.
    NonFinite {
        /// What turned non-finite.
        what: String,
    },
    /// The Newton or Broyden matrix is singular (a pivot below 1e-14 of its scale).
    SingularJacobian,
    /// The line search found no step that reduces the residual.
    LineSearchFailed,
    /// The wall-time limit was reached.
    Timeout,
    /// Interrupted from outside.
    Interrupted,
}

impl Termination {
    /// The termination for an error met while iterating: a non-finite value names where
    /// (the error's own `what`, not its message, which would say "non-finite value in" twice).
    pub fn from_error(e: &crate::Error) -> Self {
        Termination::NonFinite {
            what: match e {
                crate::Error::NonFinite { what } => what.clone(),
                other => other.to_string(),
            },
        }
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Termination::Converged => write!(f, "converged"),
            Termination::MaxIterations => write!(f, "maximum iterations reached"),
            Termination::Diverged => write!(f, "diverged"),
            Termination::NonFinite { what } => write!(f, "non-finite value in {what}"),
            Termination::SingularJacobian => write!(f, "singular Jacobian"),
            Termination::LineSearchFailed => write!(f, "line search failed to reduce the residual"),
            Termination::Timeout => write!(f, "time limit reached"),
            Termination::Interrupted => write!(f, "interrupted"),
        }
    }
}
