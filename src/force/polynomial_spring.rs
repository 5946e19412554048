//! `polynomial_spring`: `f = Σ_{p>=1} c_p u^p`.

use super::{ForceLaw, LinearPart};
use crate::error::{check_finite, Error, Result};

/// A polynomial spring, `f = Σ_{p=1}^{P} c_p u^p = c_1 u + c_2 u² + c_3 u³ + ...`,
/// evaluated by Horner's rule, `f = u (c_1 + u (c_2 + u (c_3 + ...)))`, and
/// `∂f/∂u = Σ p c_p u^{p-1}` likewise. No constant term: `f(0) = 0` (use the element's
/// `offset` to move the origin).
///
/// Its linear part is `k0 = c_1`; the rest is evaluated in the time domain.
///
/// ```
/// use hbal::force::{ForceLaw, PolynomialSpring};
/// let spring = PolynomialSpring::new(vec![1.0, 0.5, 2.0]); // u + 0.5 u² + 2 u³
/// assert_eq!(spring.force(0.0, 2.0, 0.0), 2.0 + 2.0 + 16.0);
/// assert_eq!(spring.derivatives(0.0, 2.0, 0.0), (1.0 + 2.0 + 24.0, 0.0));
/// assert_eq!(spring.linear_part().stiffness, 1.0);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolynomialSpring {
    /// `[c_1, c_2, c_3, ...]` (finite, at least one; `c_p` in N/m^p or N m/rad^p).
    pub coefficients: Vec<f64>,
}

impl PolynomialSpring {
    /// `f = Σ coefficients[p-1] u^p`.
    pub fn new(coefficients: Vec<f64>) -> Self {
        Self { coefficients }
    }
}

#[typetag::serde(name = "polynomial_spring")]
impl ForceLaw for PolynomialSpring {
    #[inline]
    fn force(&self, _theta: f64, u: f64, _du: f64) -> f64 {
        u * self
            .coefficients
            .iter()
            .rev()
            .fold(0.0, |acc, c| c + u * acc)
    }
    #[inline]
    fn derivatives(&self, _theta: f64, u: f64, _du: f64) -> (f64, f64) {
        let d = self
            .coefficients
            .iter()
            .enumerate()
            .rev()
            .fold(0.0, |acc, (i, c)| (i + 1) as f64 * c + u * acc);
        (d, 0.0)
    }
    fn linear_part(&self) -> LinearPart {
        LinearPart {
            stiffness: self.coefficients.first().copied().unwrap_or(0.0),
            damping: 0.0,
            offset: 0.0,
        }
    }
    fn validate(&self, context: &str) -> Result<()> {
        if self.coefficients.is_empty() {
            return Err(Error::invalid(
                context,
                "coefficients",
                0.0,
                "a non-empty list `[c1, c2, ...]` (number of coefficients)",
            ));
        }
        for (p, c) in self.coefficients.iter().enumerate() {
            check_finite(context, &format!("coefficients[{p}]"), *c)?;
        }
        Ok(())
    }
}
