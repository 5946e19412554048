//! A branch that holds automatic harmonics: where a point's error estimate exceeds the
//! tolerance, H is raised at that point (its solution refined to 2H, 4H, ... until within the
//! tolerance or at the cap) and the branch goes on from it on the new basis, as a new segment.
//! Where a point lies far below the tolerance ([`LOWER_BELOW`], at least [`LOWER_AFTER`]
//! points into its segment), H/2 is tried there: if its own estimate is within a quarter of
//! the tolerance, the branch goes on with H/2.

use super::{Branch, BranchStop, Continuation};
use crate::error::Result;
use crate::model::Model;
use crate::solve::{estimate_error, refine, AutoHarmonics, Control, Newton};
use crate::{HarmonicBalance, HarmonicBasis};

impl Continuation {
    /// Follows the branch of `model` from `basis.omega()` towards `to` with the error
    /// estimate at every point; where a point moving towards `to` exceeds `auto.tolerance` (in
    /// what `auto.control` controls), the segment ends there
    /// ([`BranchStop::HarmonicsChanged`]) and the next one starts from that point's solution
    /// refined to the H that meets the tolerance (at most `auto.max_harmonics`; at the cap
    /// the branch goes on at the cap's H). Where a point lies far below the tolerance, H is
    /// halved there if the halved solution still meets a quarter of it (module
    /// documentation). `basis` is the first segment's (from
    /// [`solve_auto`](crate::solve::solve_auto) at the first speed), `initial` its solution.
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
            ..self.clone()
        };
        let mut segments = Vec::new();
        let (mut basis, mut start) = (basis, initial.map(|q| q.to_vec()));
        let direction = (to - basis.omega()).signum();
        loop {
            let branch = tracer.run_from(model, basis, to, start.as_deref(), &mut progress)?;
            // Cancelled: no refinement after it, the segment's points kept as they are.
            if matches!(branch.stop, BranchStop::Cancelled { .. }) {
                segments.push(branch);
                return Ok(segments);
            }
            let capped = 2 * basis.harmonics() > auto.max_harmonics;
            let error = |i: usize| {
                let p = &branch.points[i];
                match auto.control {
                    Control::Solution => p.error_estimate,
                    Control::Harmonics => p.error_estimate_harmonics,
                    Control::Quantities => p.worst_quantity.map(|q| q.error),
                }
            };
            let forward = |i: usize| {
                let (p, q) = (&branch.points[i], &branch.points[i - 1]);
                (p.omega - q.omega) * direction > 0.0
            };
            let over = (1..branch.points.len())
                .find(|&i| forward(i) && error(i).is_some_and(|e| e > auto.tolerance));
            let under = (LOWER_AFTER..branch.points.len())
                .find(|&i| forward(i) && error(i).is_some_and(|e| e < LOWER_BELOW * auto.tolerance))
                .filter(|&j| basis.harmonics() >= 2 && over.is_none_or(|i| j < i));
            if let Some(j) = under {
                let omega = branch.points[j].omega;
                let at = basis.with_omega(omega)?;
                if let Some(lowered) = lower(
                    model,
                    at,
                    &branch.points[j].harmonics,
                    self.formulation,
                    auto,
                ) {
                    (basis, start) = end_segment(&mut segments, branch, j, &lowered);
                    continue;
                }
            }
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
            (basis, start) = end_segment(&mut segments, branch, i, &raised);
        }
    }
}

/// Ends `branch` before its point `i`, where the next segment goes on with `next` (its basis
/// and harmonics returned).
fn end_segment(
    segments: &mut Vec<Branch>,
    mut branch: Branch,
    i: usize,
    next: &crate::Solution,
) -> (HarmonicBasis, Option<Vec<num_complex::Complex64>>) {
    branch.stop = BranchStop::HarmonicsChanged {
        omega: branch.points[i].omega,
        harmonics: next.basis().harmonics(),
    };
    branch.points.truncate(i);
    segments.push(branch);
    (*next.basis(), Some(next.harmonics().to_vec()))
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
        // The next level: 2H (the estimate's reference may hold more).
        current = refine(model, &current, formulation)?;
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

/// A point's estimate below this fraction of the tolerance is far below it.
const LOWER_BELOW: f64 = 1e-2;
/// Points of a segment before H may be lowered in it (a segment starts where H changed).
const LOWER_AFTER: usize = 8;

/// The point with harmonics `q` on `basis` solved with H/2 (and N/2), if that converges and
/// its own estimate is within a quarter of the tolerance.
fn lower(
    model: &Model,
    basis: HarmonicBasis,
    q: &[num_complex::Complex64],
    formulation: crate::Formulation,
    auto: AutoHarmonics,
) -> Option<crate::Solution> {
    let n = model.n_dofs();
    let h = basis.harmonics() / 2;
    let half = HarmonicBasis::new(basis.omega(), h)
        .ok()?
        .with_tail_correction_of(&basis);
    let samples = (basis.samples() / 2).max(half.samples());
    let half = half
        .with_samples(samples)
        .ok()?
        .with_subharmonic(basis.subharmonic())
        .ok()?;
    let hb = HarmonicBalance::with_formulation(model, half, formulation).ok()?;
    let start = crate::harmonic::embed(q, n, 1, h);
    let sol = Newton::new()
        .solve_from(&hb, &start, &mut hb.workspace())
        .ok()
        .filter(|s| s.is_converged())?;
    let e = estimate_error(model, &sol).ok()?;
    (auto.control.of(&e) <= 0.25 * auto.tolerance).then_some(sol)
}
