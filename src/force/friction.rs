//! `friction`: regularised Coulomb friction `f = F_s tanh(u̇ / v_ε)`.

use super::{ForceLaw, LinearPart};
use crate::error::{check_non_negative, check_positive, Result};

/// Regularised Coulomb (dry) friction, `f = F_s tanh(u̇ / v_ε)`:
/// a force of magnitude up to `F_s` opposing the sliding velocity, smoothed over the velocity
/// scale `v_ε` (the slope at rest is `F_s / v_ε`). As `v_ε → 0` it tends to
/// `F_s sign(u̇)`; it has no stiffness and no memory (for stick with an elastic contact, a
/// Jenkins element is the model).
///
/// **Linear part.** `k0 = d0 = 0`: the force is bounded by `F_s`, so the iteration starts from
/// the system without it. The linearisation at rest (the trait's default, `d0 = F_s / v_ε`)
/// is the law's stiffest state and, for a small `v_ε`, locks the contact in the first iterate
/// whatever the excitation.
///
/// ```
/// use hbal::force::{Friction, ForceLaw};
/// let f = Friction::new(2.0, 1e-3);
/// assert!((f.force(0.0, 0.0, 0.5) - 2.0).abs() < 1e-12);   // sliding: F_s
/// assert!((f.force(0.0, 0.0, -5e-4) + 2.0 * 0.5f64.tanh()).abs() < 1e-12);
/// assert_eq!(f.derivatives(0.0, 0.0, 0.0), (0.0, 2000.0)); // F_s / v_ε at rest
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Friction {
    /// Friction limit F_s (>= 0, N or N m).
    pub limit: f64,
    /// Regularisation velocity v_ε (> 0, m/s or rad/s).
    pub regularization: f64,
}

impl Friction {
    /// Friction with limit `F_s` and regularisation velocity `v_ε`.
    pub fn new(limit: f64, regularization: f64) -> Self {
        Self {
            limit,
            regularization,
        }
    }
}

#[typetag::serde(name = "friction")]
impl ForceLaw for Friction {
    #[inline]
    fn force(&self, _theta: f64, _u: f64, du: f64) -> f64 {
        self.limit * (du / self.regularization).tanh()
    }
    #[inline]
    fn derivatives(&self, _theta: f64, _u: f64, du: f64) -> (f64, f64) {
        let t = (du / self.regularization).tanh();
        (0.0, self.limit / self.regularization * (1.0 - t * t))
    }
    fn linear_part(&self) -> LinearPart {
        LinearPart::default()
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_non_negative(context, "limit", self.limit)?;
        check_positive(context, "regularization", self.regularization)
    }
}
