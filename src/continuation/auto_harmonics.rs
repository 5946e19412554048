//! A branch that holds automatic harmonics: where a point's error estimate exceeds the
//! tolerance, H is raised at that point (its solution refined to 2H, 4H, ... until within the
//! tolerance or at the cap) and the branch goes on from it on the new basis, as a new segment.

use super::{Branch, BranchStop, Continuation};
use crate::error::Result;
use crate::model::Model;
use crate::solve::{estimate_error, refined_solution, AutoHarmonics, Control, Newton};
use crate::{HarmonicBalance, HarmonicBasis};

impl Continuation {
    /// Follows the branch of `model` from `basis.omega()` towards `to` with the error
    /// estimate at every point; where a point moving towards `to` exceeds `auto.tolerance` (in
    /// what `auto.control` controls), the segment ends there
    /// ([`BranchStop::HarmonicsRaised`]) and the next one starts from that point's solution
    /// refined to the H that meets the tolerance (at most `auto.max_harmonics`; at the cap
    /// the branch goes on at the cap's H). `basis` is the first segment's (from
    /// [`solve_auto`](crate::solve::solve_auto) at the first speed), `initial` its solution.
    /// H is only raised, never lowered.
    pub fn run_auto(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        to: f64,
        initial: Option<&[num_complex::Complex64]>,
        auto: AutoHarmonics,
        mut progress: impl FnMut(f64),
    ) -> Result<Vec<Branch>> {
        let tracer = Continuation {
            error_estimate: true,
            ..*self
        };
        let mut segments = Vec::new();
        let (mut basis, mut start) = (basis, initial.map(|q| q.to_vec()));
        let direction = (to - basis.omega()).signum();
        loop {
            let mut branch = tracer.run_from(model, basis, to, start.as_deref(), &mut progress)?;
            let capped = 2 * basis.harmonics() > auto.max_harmonics;
            let over = (1..branch.points.len()).find(|&i| {
                let (p, q) = (&branch.points[i], &branch.points[i - 1]);
                let error = match auto.control {
                    Control::Solution => p.error_estimate,
                    Control::Harmonics => p.error_estimate_harmonics,
                    Control::Quantities => p.worst_quantity.map(|q| q.error),
                };
                let forward = (p.omega - q.omega) * direction > 0.0;
                forward && error.is_some_and(|e| e > auto.tolerance)
            });
            let Some(i) = over.filter(|_| !capped) else {
                segments.push(branch);
                return Ok(segments);
            };
            let omega = branch.points[i].omega;
            let raised = raise(
                model,
                basis.with_omega(omega)?,
                &branch.points[i].harmonics,
                self.formulation,
                auto,
            )?;
            branch.points.truncate(i);
            branch.stop = BranchStop::HarmonicsRaised {
                omega,
                harmonics: raised.basis().harmonics(),
            };
            segments.push(branch);
            basis = *raised.basis();
            start = Some(raised.harmonics().to_vec());
        }
    }
}

/// The point with harmonics `q` on `basis` refined until its estimate meets the tolerance or
/// the next level would pass the cap.
fn raise(
    model: &Model,
    basis: HarmonicBasis,
    q: &[num_complex::Complex64],
    formulation: crate::Formulation,
    auto: AutoHarmonics,
) -> Result<crate::Solution> {
    let hb = HarmonicBalance::with_formulation(model, basis, formulation)?;
    let mut current = Newton::new().solve_from(&hb, q, &mut hb.workspace())?;
    loop {
        let fine = refined_solution(model, &current)?;
        current = fine;
        let next = 2 * current.basis().harmonics();
        if next > auto.max_harmonics {
            return Ok(current);
        }
        let e = estimate_error(model, &current)?;
        if auto.control.of(&e) <= auto.tolerance {
            return Ok(current);
        }
    }
}
