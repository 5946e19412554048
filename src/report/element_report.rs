//! Element outputs of many solutions of one model, such as a sweep's points: the harmonic
//! balance that gives the tail correction's forces
//! ([`HarmonicBalance::tail_forces`](crate::HarmonicBalance::tail_forces)) is built once
//! (for a large model a condensation with its rigid-body modes) and moved to each solution's
//! Ω, instead of once per solution.

use super::element_output::{outputs_with_tail, ElementOutput};
use crate::linear::Formulation;
use crate::model::Model;
use crate::solution::Solution;
use crate::{HarmonicBalance, Result};
use num_complex::Complex64;

/// [`element_outputs`](super::element_outputs) of one model, for many solutions.
///
/// ```
/// use hbal::force::{MeshDamping, MeshProfile, MeshStiffness};
/// use hbal::report::{element_outputs, ElementReport};
/// use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
/// // A mesh whose stiffness jumps: its force includes the tail correction's part.
/// let profile = MeshProfile::Rectangular { one_tooth: 1.0, two_tooth: 1.5, contact_ratio: 1.6 };
/// let model = Model::builder(&["x"])
///     .mass_diagonal(&[1.0])
///     .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.05))
///     .element("mesh", &[("x", 1.0)], MeshStiffness::new(1, profile, MeshDamping::Constant(0.0)))
///     .load("x", 0, 0.2, 0.0)
///     .build()?;
/// let mut report = ElementReport::new(&model);
/// for omega in [0.3, 0.35] {
///     let basis = HarmonicBasis::new(omega, 16)?.with_tail_correction(true);
///     let hb = HarmonicBalance::new(&model, basis)?;
///     let sol = Newton::new().solve(&hb, &mut hb.workspace())?;
///     // The same force as from a harmonic balance built for this solution alone.
///     let (reused, alone) = (&report.outputs(&sol)?[0].force, &element_outputs(&model, &sol)?[0].force);
///     for (a, b) in reused.harmonics.iter().zip(&alone.harmonics) {
///         assert!((a - b).norm() < 1e-12);
///     }
/// }
/// # Ok::<(), hbal::Error>(())
/// ```
pub struct ElementReport<'m> {
    model: &'m Model,
    /// Whether a law of the model can have a tail correction.
    candidate: bool,
    /// The harmonic balance of the last solution whose basis had the correction on.
    hb: Option<HarmonicBalance<'m>>,
}

impl<'m> ElementReport<'m> {
    /// The element outputs of `model`'s solutions.
    pub fn new(model: &'m Model) -> Self {
        let candidate = model
            .elements()
            .iter()
            .any(|e| crate::residual::tail_corrects(e.law()));
        Self {
            model,
            candidate,
            hb: None,
        }
    }

    /// The outputs of every element on the periodic solution `sol` (a solution of the model
    /// this report was made for).
    pub fn outputs(&mut self, sol: &Solution) -> Result<Vec<ElementOutput>> {
        let tail = self.tail_forces(sol)?;
        outputs_with_tail(self.model, sol, tail)
    }

    /// The force harmonics the tail correction added to the elements it corrects, from a
    /// harmonic balance of the same basis (the last one, moved to this Ω, where only Ω
    /// differs); none (and no discretisation) where no law can have it.
    fn tail_forces(&mut self, sol: &Solution) -> Result<Vec<(usize, Vec<Complex64>)>> {
        let basis = *sol.basis();
        if !self.candidate || !basis.tail_correction() || basis.harmonics() == 0 {
            return Ok(Vec::new());
        }
        let reusable = self
            .hb
            .as_ref()
            .is_some_and(|hb| basis.with_omega(hb.basis().omega()).ok() == Some(*hb.basis()));
        let moved = match self.hb.as_mut().filter(|_| reusable) {
            Some(hb) if hb.basis().omega() == basis.omega() => true,
            Some(hb) => hb.set_omega(basis.omega()).is_ok(),
            None => false,
        };
        if !moved {
            // Either formulation gives the same receptances; the full one where `auto` cannot
            // condense.
            let model = self.model;
            let hb = HarmonicBalance::with_formulation(model, basis, Formulation::Auto)
                .or_else(|_| HarmonicBalance::with_formulation(model, basis, Formulation::Full))?;
            self.hb = Some(hb);
        }
        Ok(self
            .hb
            .as_ref()
            .map(|hb| hb.tail_forces(sol.harmonics()))
            .unwrap_or_default())
    }
}
