//! `linear_spring`: `f = k u + d u̇`.

use super::{ForceLaw, LinearPart};
use crate::error::{check_non_negative, Result};

/// A linear spring-damper, `f = k u + d u̇`; it lives entirely in `K0`, `D0`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearSpring {
    /// Stiffness k (>= 0).
    pub k: f64,
    /// Damping d (>= 0), default 0.
    #[serde(default)]
    pub d: f64,
}

impl LinearSpring {
    /// A spring of stiffness `k` and damping `d`.
    pub fn new(k: f64, d: f64) -> Self {
        Self { k, d }
    }
}

#[typetag::serde(name = "linear_spring")]
impl ForceLaw for LinearSpring {
    fn force(&self, _theta: f64, u: f64, du: f64) -> f64 {
        self.k * u + self.d * du
    }
    fn derivatives(&self, _theta: f64, _u: f64, _du: f64) -> (f64, f64) {
        (self.k, self.d)
    }
    fn linear_part(&self) -> LinearPart {
        LinearPart {
            stiffness: self.k,
            damping: self.d,
            offset: 0.0,
        }
    }
    fn is_linear_time_invariant(&self) -> bool {
        true
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_non_negative(context, "k", self.k)?;
        check_non_negative(context, "d", self.d)
    }
}
