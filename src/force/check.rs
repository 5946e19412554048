//! A finite-difference check of a law's derivatives, for built-in and user laws.

use super::ForceLaw;

/// Result of [`check_derivatives`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DerivativeCheck {
    /// Largest `|analytic - finite difference| / max(1, |analytic|)` over all points and both
    /// derivatives.
    pub max_relative_error: f64,
    /// The point `(θ, u, u̇)` where it occurred.
    pub worst_point: (f64, f64, f64),
}

/// Compares [`ForceLaw::derivatives`] with central differences at the given points `(θ, u, u̇)`.
///
/// The step is `1e-6 max(1, |x|)`; keep points away from kinks (contact edges), where a
/// central difference averages both sides.
pub fn check_derivatives(law: &dyn ForceLaw, points: &[(f64, f64, f64)]) -> DerivativeCheck {
    let mut worst = DerivativeCheck {
        max_relative_error: 0.0,
        worst_point: (0.0, 0.0, 0.0),
    };
    for &(theta, u, du) in points {
        let (dfdu, dfddu) = law.derivatives(theta, u, du);
        let hu = 1e-6 * u.abs().max(1.0);
        let hd = 1e-6 * du.abs().max(1.0);
        let fd_u = (law.force(theta, u + hu, du) - law.force(theta, u - hu, du)) / (2.0 * hu);
        let fd_d = (law.force(theta, u, du + hd) - law.force(theta, u, du - hd)) / (2.0 * hd);
        for (analytic, numeric) in [(dfdu, fd_u), (dfddu, fd_d)] {
            let err = (analytic - numeric).abs() / analytic.abs().max(1.0);
            if err > worst.max_relative_error || err.is_nan() {
                worst = DerivativeCheck {
                    max_relative_error: err,
                    worst_point: (theta, u, du),
                };
            }
        }
    }
    worst
}
