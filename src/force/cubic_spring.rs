//! `cubic_spring` (Duffing): `f = k u + α u³ + d u̇`.

use super::{ForceLaw, LinearPart};
use crate::error::{check_finite, check_non_negative, Result};

/// A cubic (Duffing) spring, `f = k u + α u³ + d u̇`.
///
/// Its linear part is `(k, d)`; only `α u³` is evaluated in the time domain.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CubicSpring {
    /// Linear stiffness k (finite; may be negative for a double-well oscillator).
    pub k: f64,
    /// Cubic coefficient α (finite; > 0 hardening, < 0 softening).
    pub alpha: f64,
    /// Linear damping d (>= 0), default 0.
    #[serde(default)]
    pub d: f64,
}

impl CubicSpring {
    /// `f = k u + α u³`.
    pub fn new(k: f64, alpha: f64) -> Self {
        Self { k, alpha, d: 0.0 }
    }
}

#[typetag::serde(name = "cubic_spring")]
impl ForceLaw for CubicSpring {
    fn force(&self, _theta: f64, u: f64, du: f64) -> f64 {
        self.k * u + self.alpha * u * u * u + self.d * du
    }
    fn derivatives(&self, _theta: f64, u: f64, _du: f64) -> (f64, f64) {
        (self.k + 3.0 * self.alpha * u * u, self.d)
    }
    fn linear_part(&self) -> LinearPart {
        LinearPart {
            stiffness: self.k,
            damping: self.d,
            offset: 0.0,
        }
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_finite(context, "k", self.k)?;
        check_finite(context, "alpha", self.alpha)?;
        check_non_negative(context, "d", self.d)
    }
}
