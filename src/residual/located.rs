//! Where an element's samples turned non-finite: the element, the shaft angle of the first bad
//! sample and the coordinate there, so that a [`Termination`](crate::Termination) or an error
//! says where instead of passing NaN on.

use crate::error::{Error, Result};

/// The samples of one element in an AFT pass: shaft angles, coordinate and its rate.
pub(super) struct Samples<'a> {
    pub(super) thetas: &'a [f64],
    pub(super) u: &'a [f64],
    pub(super) du: &'a [f64],
}

impl Samples<'_> {
    /// `Ok` if every value is finite, else an error naming `what` of `element` at the first
    /// sample that is not (`values` may hold several quantities one after the other, sample
    /// by sample).
    pub(super) fn check(&self, what: &str, element: &str, values: &[f64]) -> Result<()> {
        let Some(i) = values.iter().position(|v| !v.is_finite()) else {
            return Ok(());
        };
        let j = i % self.thetas.len().max(1);
        let at = |v: &[f64]| v.get(j).copied().unwrap_or(f64::NAN);
        Err(Error::NonFinite {
            what: format!(
                "{what} of element `{element}` at θ = {:.6} rad (u = {:e}, u̇ = {:e})",
                at(self.thetas),
                at(self.u),
                at(self.du)
            ),
        })
    }
}

impl super::HarmonicBalance<'_> {
    /// The element samples now in `b` (after `element_samples`).
    pub(super) fn samples<'a>(&'a self, b: &'a super::AftBuffers) -> Samples<'a> {
        Samples {
            thetas: &self.thetas,
            u: &b.u,
            du: &b.du,
        }
    }
}
