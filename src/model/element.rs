//! A force element: a [`ForceLaw`] on the local coordinate `u = w·q`.

use super::GearStage;
use crate::force::{ForceLaw, LinearPart};

/// A force element: law `f(θ, u, u̇)` on `u = w·q`, acting back as `-w f`.
///
/// A gear mesh between two shafts with base radii `r1`, `r2` is one element with weights
/// `(r1, -r2)` (or `(1, -i)` for a transmission ratio i), best built as a [`GearStage`];
/// a 1-DOF model has weight 1.
#[derive(Debug)]
pub struct Element {
    pub(crate) name: String,
    pub(crate) weights: Vec<(usize, f64)>,
    pub(crate) law: Box<dyn ForceLaw>,
    pub(crate) linear: LinearPart,
    /// The gear stage it was built from, if any.
    pub(crate) stage: Option<GearStage>,
}

impl Element {
    /// The element's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Its weights as `(DOF index, w_i)`.
    pub fn weights(&self) -> &[(usize, f64)] {
        &self.weights
    }

    /// Its force law.
    pub fn law(&self) -> &dyn ForceLaw {
        self.law.as_ref()
    }

    /// The gear stage this element models, if it was built as one.
    pub fn gear_stage(&self) -> Option<&GearStage> {
        self.stage.as_ref()
    }

    /// Its constant linear part `(k0, d0)`.
    pub fn linear_part(&self) -> LinearPart {
        self.linear
    }

    /// `u = w·x` for a vector `x` indexed by DOF.
    #[inline]
    pub fn gather<T>(&self, x: &[T]) -> T
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T> + Default,
    {
        self.weights
            .iter()
            .fold(T::default(), |acc, &(i, w)| acc + x[i] * w)
    }

    /// `out += w f`.
    #[inline]
    pub fn scatter_add<T>(&self, f: T, out: &mut [T])
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::AddAssign,
    {
        for &(i, w) in &self.weights {
            out[i] += f * w;
        }
    }
}
