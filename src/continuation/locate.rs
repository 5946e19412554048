//! Locating a bifurcation on a branch: regula falsi (Illinois) on a test function of the
//! Floquet multipliers (the exact orbits', or the HB orbits' own where the shooting found another
//! orbit, see `stability::orbit_distance`), between the two points whose stability changed, each
//! trial point corrected onto the branch (branch switching starts from it, see `switch`).

use super::bordered::{Scales, Target, Tracer};
use super::{Branch, Continuation};
use crate::error::Result;
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solution::Solution;
use crate::stability::{Bifurcation, Floquet};
use crate::HarmonicBasis;
use num_complex::Complex64;

/// Regula falsi steps locating a branch point.
const LOCATE_STEPS: usize = 30;

impl Continuation {
    /// Sets [`BranchPoint::bifurcation_omega`](super::BranchPoint::bifurcation_omega) of every
    /// point of `branch` (on `basis`) that closes a stability change other than a fold.
    pub(super) fn locate_bifurcations(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        branch: &mut Branch,
    ) -> Result<()> {
        if self.stability.is_none() {
            return Ok(());
        }
        for i in 1..branch.points.len() {
            let kind = match branch.points[i].bifurcation {
                Some(Bifurcation::Fold) | None => continue,
                Some(k) => k,
            };
            let (a, b) = (&branch.points[i - 1], &branch.points[i]);
            // A failure leaves the point as it is: the bifurcation is still reported there.
            if let Ok(Some((_, omega))) = self.locate(model, basis, a, b, kind) {
                branch.points[i].bifurcation_omega = Some(omega);
            }
        }
        Ok(())
    }

    /// The orbit on the parent branch (on its basis) between the points `a` and `b` where the
    /// critical multiplier of `kind` passes through the unit circle: regula falsi (Illinois)
    /// on the arclength along the chord from `a` to `b`, each trial corrected onto the branch
    /// on the hyperplane normal to the chord. `None` without a crossing.
    pub(super) fn locate(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        a: &super::BranchPoint,
        b: &super::BranchPoint,
        kind: Bifurcation,
    ) -> Result<Option<(Vec<Complex64>, f64)>> {
        // Every trial on the exact orbit (a single analysis of the HB orbit's would measure
        // it against the exact orbit's anyway).
        let options = crate::stability::FloquetOptions {
            orbit: crate::stability::Orbit::Exact,
            ..self.stability.unwrap_or_default()
        };
        let (Some(fa), Some(fb)) = (
            a.floquet.as_ref().and_then(|f| critical_value(f, kind)),
            b.floquet.as_ref().and_then(|f| critical_value(f, kind)),
        ) else {
            return Ok(None);
        };
        if fa * fb > 0.0 {
            return Ok(None);
        }
        let hb = HarmonicBalance::with_formulation(model, basis, self.formulation)?;
        let layout = hb.layout();
        let m = layout.len();
        let (mut xa, mut xb) = (vec![0.0; m], vec![0.0; m]);
        let (Some(ua), Some(ub)) = (
            hb.unknowns_of_full(&a.harmonics),
            hb.unknowns_of_full(&b.harmonics),
        ) else {
            return Ok(None);
        };
        layout.pack(&ua, &mut xa);
        layout.pack(&ub, &mut xb);
        let mut tr = Tracer::new(hb, Scales::new(0.0, a.omega, 1.0));
        tr.sc = Scales::new(tr.rms(&xa), a.omega, tr.load_norm());
        let (chord, h) = tr.chord(&xa, a.omega, &xb, b.omega);
        let (mut s0, mut f0, mut s1, mut f1) = (0.0, fa, h, fb);
        let mut best = if fa.abs() < fb.abs() {
            (a.harmonics.clone(), a.omega)
        } else {
            (b.harmonics.clone(), b.omega)
        };
        let mut xp = vec![0.0; m];
        let mut kept = false;
        for _ in 0..LOCATE_STEPS {
            let s = (s0 * f1 - s1 * f0) / (f1 - f0);
            if !s.is_finite() {
                return Ok(None);
            }
            if (s1 - s0).abs() < 1e-10 * h {
                break;
            }
            let op = tr.sc.predict(&xa, a.omega, &chord, s, &mut xp);
            let (mut xc, mut oc) = (xp.clone(), op);
            let target = Target {
                xp: &xp,
                op,
                row: &chord,
                chord: false,
            };
            let Some((_, rel)) = self.correct(&mut tr, &mut xc, &mut oc, &target) else {
                return Ok(None);
            };
            let mut unknowns = vec![Complex64::default(); tr.hb.len()];
            layout.unpack(&xc, &mut unknowns);
            // All DOFs (`tr.hb` sits at `oc` after the corrector).
            let Ok(q) = tr.hb.full_harmonics(&unknowns, &mut tr.hb.workspace().eval) else {
                return Ok(None);
            };
            let sol = Solution::from_harmonics(
                basis.with_omega(oc)?,
                model.dof_names().to_vec(),
                q,
                rel,
            )?;
            best = (sol.harmonics().to_vec(), oc);
            let Some(f) = options
                .compute(model, &sol)
                .ok()
                .and_then(|fl| critical_value(&fl, kind))
            else {
                return Ok(None);
            };
            if f.abs() < 1e-11 {
                break;
            }
            // Illinois: halve the end value kept twice in a row.
            if f * f1 < 0.0 {
                (s0, f0) = (s1, f1);
                kept = false;
            } else {
                if kept {
                    f0 *= 0.5;
                }
                kept = true;
            }
            (s1, f1) = (s, f);
        }
        Ok(Some(best))
    }
}

/// A test function of `kind` that changes sign where the bifurcation happens, continuous
/// along the branch: `Π (μ_i - 1)` for a branch point or fold (zero where a real multiplier
/// is +1; a complex pair contributes `|μ - 1|² > 0`, so a pair that turns real on the way
/// does not hide the crossing), `Π (μ_i + 1)` for a period doubling, and `|μ| - 1` of the
/// largest complex multiplier for a Neimark–Sacker point. Each factor is divided by
/// `max(1, |μ_i|)` against overflow.
fn critical_value(f: &Floquet, kind: Bifurcation) -> Option<f64> {
    let shift = match kind {
        Bifurcation::PeriodDoubling => 1.0,
        Bifurcation::NeimarkSacker => {
            return f
                .multipliers
                .iter()
                .find(|m| m.im.abs() > 1e-9 * m.norm().max(1.0))
                .map(|m| m.norm() - 1.0);
        }
        _ => -1.0,
    };
    let p = f.multipliers.iter().fold(Complex64::new(1.0, 0.0), |p, m| {
        p * (m + shift) / m.norm().max(1.0)
    });
    p.re.is_finite().then_some(p.re)
}
