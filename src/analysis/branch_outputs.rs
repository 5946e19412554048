//! What a branch's points say in element terms: every element's output at every point (for
//! the order cuts), and the speed ranges over which a contact opens for part of the period.

use crate::continuation::Branch;
use crate::model::Model;
use crate::report::{ElementOutput, ElementReport};
use crate::{HarmonicBasis, Result, Solution};

/// A speed range over which a contact opens for part of the period.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ContactLoss {
    /// The contact element.
    pub element: String,
    /// The first speed (the scene's unit) of the range.
    pub from: f64,
    /// The last speed.
    pub to: f64,
    /// The largest fraction of the period it is open.
    pub max_open: f64,
}

/// The element outputs of every point of `branch` (computed on `basis`).
pub fn point_outputs(
    model: &Model,
    branch: &Branch,
    basis: &HarmonicBasis,
) -> Result<Vec<Vec<ElementOutput>>> {
    let mut report = ElementReport::new(model);
    branch
        .points
        .iter()
        .map(|p| {
            let sol = Solution::from_harmonics(
                basis.with_omega(p.omega)?,
                branch.dofs.clone(),
                p.harmonics.clone(),
                p.residual,
            )?;
            report.outputs(&sol)
        })
        .collect()
}

/// The ranges of consecutive points of `branch` where an element with an `open` state opens
/// (more than 0.1 % of the period), in the speed unit of `speed`.
pub fn contact_loss(
    model: &Model,
    branch: &Branch,
    outputs: &[Vec<ElementOutput>],
    speed: impl Fn(f64) -> f64,
) -> Vec<ContactLoss> {
    let contacts: Vec<usize> = (0..model.elements().len())
        .filter(|&i| model.elements()[i].law().state_names().contains(&"open"))
        .collect();
    let mut out = Vec::new();
    let mut open: Vec<Option<ContactLoss>> = vec![None; contacts.len()];
    for (p, outputs) in branch.points.iter().zip(outputs) {
        let s = speed(p.omega);
        for (slot, &i) in open.iter_mut().zip(&contacts) {
            let fraction = outputs[i]
                .states
                .iter()
                .find(|(n, _)| n == "open")
                .map_or(0.0, |(_, f)| *f);
            match (slot.as_mut(), fraction > 1e-3) {
                (Some(run), true) => {
                    run.from = run.from.min(s);
                    run.to = run.to.max(s);
                    run.max_open = run.max_open.max(fraction);
                }
                (None, true) => {
                    *slot = Some(ContactLoss {
                        element: outputs[i].name.clone(),
                        from: s,
                        to: s,
                        max_open: fraction,
                    })
                }
                (Some(_), false) => out.extend(slot.take()),
                (None, false) => {}
            }
        }
    }
    out.extend(open.into_iter().flatten());
    out
}
