//! External load harmonics.

/// One load harmonic on one DOF: `f_dof(t) += cos · cos(k Ω t) + sin · sin(k Ω t)`.
///
/// Order `k = 0` is a static load (its `sin` is ignored).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Load {
    /// DOF index.
    pub dof: usize,
    /// Harmonic order k of the fundamental.
    pub order: usize,
    /// Cosine amplitude.
    pub cos: f64,
    /// Sine amplitude.
    pub sin: f64,
}
