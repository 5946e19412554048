//! Solvers on the harmonic residual `R(Q) = Z Q + F_rest(Q) - F_ext`.
//!
//! [`FixedPoint`] is the paper's iteration (section 3, steps 2a-2e).

mod fixed_point;

pub use fixed_point::FixedPoint;
