//! Branch switching: the branches that leave a branch at a simple branch point (symmetry
//! breaking) or a period doubling.
//!
//! At a simple branch point `y* = (x*, Ω*)` the Jacobian `[R_x R_Ω]` has a two-dimensional null
//! space: the tangent `t` of the known branch and a second direction `φ` along which the new
//! branch leaves (Keller's perpendicular switching; see Seydel, *Practical Bifurcation and
//! Stability Analysis*, 3rd ed., §5.6). Here
//!
//! 1. the branch point is located between the two points of the parent branch whose stability
//!    changed, where the critical Floquet multiplier of the exact orbit passes through +1
//!    (−1 for a period doubling): regula falsi (Illinois) on `μ − 1` along the parent branch,
//!    each trial point corrected onto it on the hyperplane normal to the chord. The exact
//!    multipliers place it to about 1e-9; the sign of the HB Jacobian's determinant would not:
//!    with a contact kink the AFT Jacobian is exact only to O(1/N) (a sample switching sides
//!    jumps it), which moves the branch point of the chain example by 2e-4 at N = 2048;
//! 2. `φ` is the eigenvector of the bordered matrix `[[R_x s_x, R_Ω s_Ω], [tᵀ]]` at `y*` with
//!    the eigenvalue closest to zero (inverse iteration with its factors), made orthogonal to
//!    the parent's tangent `t`;
//! 3. the first point of the new branch is `y* ± s φ`, corrected on the hyperplane normal to
//!    `φ`, and the new branch is followed from there to the end of the range, leaving `y*`.
//!
//! A period doubling of a T-periodic orbit is a branch point of the same orbit seen as
//! 2T-periodic: on the doubled basis ([`HarmonicBasis::doubled`]) the parent's harmonics are
//! the even ones, a Floquet multiplier through −1 of the T-map is a multiplier through +1 of the
//! 2T-map, and `φ` holds only odd harmonics. Both signs of `φ` give the same period-2 orbit
//! shifted by T, so one side is followed.

use super::arclength::Range;
use super::bordered::{tangent, Scales, Target, Tracer};
use super::{Branch, BranchStop, Continuation, Origin};
use crate::error::Result;
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solution::Solution;
use crate::stability::Bifurcation;
use crate::HarmonicBasis;
use num_complex::Complex64;

impl Continuation {
    /// The branches leaving `parent` (computed on `basis`: its H, N and ν; its Ω is ignored)
    /// at its branch points (both sides) and period doublings (on the doubled basis), each
    /// followed until it leaves `[lo, hi]` (or stops).
    ///
    /// A bifurcation where the switch does not succeed (the determinant does not change sign,
    /// or no new orbit is found next to it) gives a branch without points whose `stop` says
    /// why, so the caller can report it.
    pub fn switch_branches(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        parent: &Branch,
        lo: f64,
        hi: f64,
    ) -> Result<Vec<Branch>> {
        let mut out: Vec<Branch> = Vec::new();
        for i in 1..parent.points.len() {
            if self.cancel.is_cancelled() {
                break;
            }
            let kind = match parent.points[i].bifurcation {
                Some(k @ (Bifurcation::BranchPoint | Bifurcation::PeriodDoubling)) => k,
                _ => continue,
            };
            // A branch switched earlier that came back here is this bifurcation's branch.
            let (a, b) = (parent.points[i - 1].omega, parent.points[i].omega);
            let margin = 0.5 * (b - a).abs();
            let known = out.iter().any(|br| match br.stop {
                BranchStop::Rejoined { omega } => {
                    omega >= a.min(b) - margin && omega <= a.max(b) + margin
                }
                _ => false,
            });
            if known {
                continue;
            }
            let on = match kind {
                Bifurcation::PeriodDoubling => basis.doubled()?,
                _ => basis,
            };
            out.extend(self.switch_at(model, on, parent, i, kind, lo, hi)?);
        }
        Ok(out)
    }

    /// The branches leaving `parent` between its points `i - 1` and `i`, on `basis`.
    #[allow(clippy::too_many_arguments)]
    fn switch_at(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        parent: &Branch,
        i: usize,
        kind: Bifurcation,
        lo: f64,
        hi: f64,
    ) -> Result<Vec<Branch>> {
        let (pa, pb) = (&parent.points[i - 1], &parent.points[i]);
        let failed = |omega: f64, why: &str| {
            let mut b = Branch::new(model, basis, String::new());
            b.origin = Some(Origin {
                bifurcation: kind,
                omega,
                parent_point: i,
                side: 0,
                max_abs: Vec::new(),
            });
            b.stop = BranchStop::SwitchFailed { reason: why.into() };
            vec![b]
        };
        let ratio = basis.subharmonic() / parent.subharmonic.max(1);
        if ratio == 0 || ratio * parent.subharmonic.max(1) != basis.subharmonic() {
            return Ok(failed(pb.omega, "the basis does not contain the parent's"));
        }
        // The parent's own period multiple (a branch born at an earlier period doubling has 2).
        let parent_basis = HarmonicBasis::new(pa.omega, parent.harmonics)?
            .with_tail_correction_of(&basis)
            .with_subharmonic(parent.subharmonic.max(1))?
            .with_samples(basis.samples() / ratio)?;
        // 1. Locate the branch point on the parent branch.
        let Some((q_star, o_star)) = self.locate(model, parent_basis, pa, pb, kind)? else {
            return Ok(failed(
                0.5 * (pa.omega + pb.omega),
                "the critical multiplier does not cross between the points",
            ));
        };
        // 2. The parent branch and its second null direction on `basis`.
        let hb =
            HarmonicBalance::with_formulation(model, basis.with_omega(o_star)?, self.formulation)?;
        let layout = hb.layout();
        let m = layout.len();
        // Full harmonics on the parent's basis, embedded in `basis`, as unknowns (all DOFs, or
        // the element coordinates when condensed).
        let pack = |q: &[Complex64]| {
            let embedded = crate::harmonic::embed(q, model.n_dofs(), ratio, basis.harmonics());
            let unknowns = hb.unknowns_of_full(&embedded)?;
            let mut x = vec![0.0; m];
            layout.pack(&unknowns, &mut x);
            Some(x)
        };
        let (Some(xa), Some(xb), Some(x_star)) =
            (pack(&pa.harmonics), pack(&pb.harmonics), pack(&q_star))
        else {
            return Ok(failed(o_star, "the branch points do not match the basis"));
        };
        let max_abs: Vec<f64> = Solution::from_harmonics(
            parent_basis.with_omega(o_star)?,
            model.dof_names().to_vec(),
            q_star.clone(),
            0.0,
        )
        .map(|s| s.max_abs_all())
        .unwrap_or_default();
        let mut tr = Tracer::new(hb, Scales::new(0.0, o_star, 1.0));
        tr.sc = Scales::new(tr.rms(&x_star), o_star, tr.load_norm());
        // The chord from a, or to b if the branch point sits on a.
        let (xe, oe) = if tr.distance(&x_star, o_star, &xa, pa.omega) > 0.0 {
            (&xa, pa.omega)
        } else {
            (&xb, pb.omega)
        };
        let (mut t, _) = tr.chord(xe, oe, &x_star, o_star);
        let Some(phi) = null_direction(&mut tr, &x_star, o_star, &mut t) else {
            return Ok(failed(
                o_star,
                "no second null direction at the branch point",
            ));
        };
        // The unknowns that vanish on the parent (a symmetry it keeps): when φ lives there, the
        // new branch has rejoined the parent once they vanish again.
        let top = x_star.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        let mask: Vec<bool> = x_star.iter().map(|v| v.abs() <= 1e-12 * top).collect();
        let phi_inside: f64 = phi
            .iter()
            .zip(&mask)
            .filter(|(_, m)| **m)
            .map(|(v, _)| v * v)
            .sum();
        let rejoin = (phi_inside > 0.5).then_some(mask.as_slice());
        // 3. Both sides (one for a period doubling: the other is the same orbit shifted by T).
        let sides: &[i8] = match kind {
            Bifurcation::PeriodDoubling => &[1],
            _ => &[1, -1],
        };
        let step = tr.distance(&xb, pb.omega, &xa, pa.omega);
        // Each side starts from the branch point's scales (following a side rescales `tr`).
        let scales = tr.sc;
        let mut out = Vec::new();
        for &side in sides {
            tr.sc = scales;
            let mut branch = Branch::new(model, basis, format!("{kind:?} switch"));
            branch.origin = Some(Origin {
                bifurcation: kind,
                omega: o_star,
                parent_point: i,
                side,
                max_abs: max_abs.clone(),
            });
            let dir: Vec<f64> = phi.iter().map(|v| v * f64::from(side)).collect();
            let Some((x, omega, rel)) = self.first_point(&mut tr, &x_star, o_star, &dir, step)
            else {
                branch.stop = BranchStop::SwitchFailed {
                    reason: "the corrector found no new orbit next to the branch point".into(),
                };
                out.push(branch);
                continue;
            };
            // Tangent at the new point, leaving the branch point (φᵀ t > 0).
            let mut t_new = vec![0.0; m + 1];
            if tr.factor(&x, omega, &dir)?.is_none() {
                branch.stop = BranchStop::Singular { omega };
                out.push(branch);
                continue;
            }
            tangent(&mut tr.b, &mut t_new);
            if let Some(reason) = self.push(&mut branch, model, &tr.hb, &x, omega, rel) {
                branch.stop = BranchStop::StabilityFailed { omega, reason };
                out.push(branch);
                continue;
            }
            // Either end of the range ends it (it may leave the branch point vertically, as
            // the period-2 orbits of a linear contact do, and turn either way).
            let (back, to) = if t_new[m] >= 0.0 { (lo, hi) } else { (hi, lo) };
            let range = Range {
                back: Some(back),
                to,
                rejoin,
            };
            self.follow(&mut tr, model, &mut branch, x, omega, t_new, range, |_| {});
            self.locate_bifurcations(model, basis, &mut branch)?;
            out.push(branch);
        }
        Ok(out)
    }

    /// The first point of the new branch: `y* + s φ` corrected on the hyperplane normal to
    /// `φ`, for a step `s` from `h` down to `h/64`.
    fn first_point(
        &self,
        tr: &mut Tracer,
        x_star: &[f64],
        o_star: f64,
        phi: &[f64],
        h: f64,
    ) -> Option<(Vec<f64>, f64, f64)> {
        let m = x_star.len();
        let mut xp = vec![0.0; m];
        let mut s = h.clamp(1e-4, self.max_step);
        for _ in 0..7 {
            let op = tr.sc.predict(x_star, o_star, phi, s, &mut xp);
            let (mut xc, mut oc) = (xp.clone(), op);
            let target = Target {
                xp: &xp,
                op,
                row: phi,
                chord: false,
            };
            if let Some((_, rel)) = self.correct(tr, &mut xc, &mut oc, &target) {
                return Some((xc, oc, rel));
            }
            s *= 0.5;
        }
        None
    }
}

/// The second null direction `φ` at the branch point `(x*, Ω*)`: inverse iteration with the
/// bordered matrix (last row `t`, on entry the chord to `(x*, Ω*)` and on return the parent's
/// tangent there), then made orthogonal to that tangent. Unit length in the scaled unknowns.
fn null_direction(tr: &mut Tracer, x: &[f64], omega: f64, t: &mut [f64]) -> Option<Vec<f64>> {
    let m = x.len();
    tr.factor(x, omega, t).ok()??;
    let mut t_star = vec![0.0; m + 1];
    tangent(&mut tr.b, &mut t_star);
    t.copy_from_slice(&t_star);
    // A fixed start with components in every direction.
    let mut v: Vec<f64> = (0..=m).map(|k| (1.7 * k as f64 + 0.3).sin()).collect();
    for _ in 0..4 {
        tr.b.solve(&mut v);
        let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        v.iter_mut().for_each(|a| *a /= norm);
    }
    let along: f64 = v.iter().zip(&t_star).map(|(a, b)| a * b).sum();
    v.iter_mut().zip(&t_star).for_each(|(a, b)| *a -= along * b);
    let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
    (norm > 1e-3).then(|| v.iter().map(|a| a / norm).collect())
}
