//! Large models: the monodromy matrix on a reduced basis, or no matrix at all.
//!
//! [`modes`] computes the undamped modes of `(K0, M)` below a cut-off (sparse Cholesky of
//! `K0 + σM`, shift-invert subspace iteration); [`reduction`] builds the basis `V` of those
//! modes plus the static attachment modes of the element coordinates, on which the shooting
//! runs as on the full model. [`krylov_floquet`] finds the leading multipliers by the Arnoldi
//! iteration ([`arnoldi`]) on the monodromy action integrated in the model's own sparse
//! matrices ([`sparse_action`]), for long chains with every mode in the excitation band.
//! Uses the HB state and the rate bound; used by the method choice.

pub(crate) mod arnoldi;
pub(crate) mod krylov_floquet;
pub(crate) mod modes;
pub(crate) mod reduction;
pub(crate) mod sparse_action;
