//! `quadratic_damper`: `f = c u̇ |u̇|`.

use super::{ForceLaw, LinearPart};
use crate::error::{check_non_negative, Result};

/// A quadratic (turbulent, hydraulic) damper, `f = c u̇ |u̇|`, `∂f/∂u̇ = 2 c |u̇|`.
///
/// The force is C¹ in `u̇` (its second derivative jumps at `u̇ = 0`), so its harmonics fall
/// like `k⁻³`. Its linear part is zero, the linearisation at rest.
///
/// ```
/// use hbal::force::{ForceLaw, QuadraticDamper};
/// let damper = QuadraticDamper::new(2.0);
/// assert_eq!(damper.force(0.0, 0.0, -3.0), -18.0);
/// assert_eq!(damper.derivatives(0.0, 0.0, -3.0), (0.0, 12.0));
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadraticDamper {
    /// Coefficient c (>= 0, N s²/m² or N m s²/rad²).
    pub c: f64,
}

impl QuadraticDamper {
    /// A damper `f = c u̇ |u̇|`.
    pub fn new(c: f64) -> Self {
        Self { c }
    }
}

#[typetag::serde(name = "quadratic_damper")]
impl ForceLaw for QuadraticDamper {
    #[inline]
    fn force(&self, _theta: f64, _u: f64, du: f64) -> f64 {
        self.c * du * du.abs()
    }
    #[inline]
    fn derivatives(&self, _theta: f64, _u: f64, du: f64) -> (f64, f64) {
        (0.0, 2.0 * self.c * du.abs())
    }
    fn linear_part(&self) -> LinearPart {
        LinearPart::default()
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_non_negative(context, "c", self.c)
    }
}
