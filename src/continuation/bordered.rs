//! The corrector of pseudo-arclength continuation: the bordered system
//! `[[R_x s_x, R_Ω s_Ω], [rowᵀ]]`, Newton towards a target on a hyperplane, the tangent, and
//! the location of turning points.

// The corrector indexes several vectors in lock step.
#![allow(clippy::needless_range_loop)]

use super::Continuation;
use crate::error::{Error, Result};
use crate::harmonic::RealLayout;
use crate::residual::{HarmonicBalance, Workspace};
use crate::solve::lu;
use nalgebra::DMatrix;

/// Buffers of the corrector.
pub(super) struct Bordered {
    pub(super) layout: RealLayout,
    pub(super) r: Vec<f64>,
    pub(super) r_omega: Vec<f64>,
    pub(super) jac: DMatrix<f64>,
    pub(super) big: DMatrix<f64>,
    pub(super) perm: Vec<usize>,
    pub(super) rhs: Vec<f64>,
}

impl Bordered {
    pub(super) fn new(layout: RealLayout) -> Self {
        let m = layout.len();
        Self {
            layout,
            r: vec![0.0; m],
            r_omega: vec![0.0; m],
            jac: DMatrix::zeros(m, m),
            big: DMatrix::zeros(m + 1, m + 1),
            perm: vec![0; m + 1],
            rhs: vec![0.0; m + 1],
        }
    }

    /// Evaluates R, R_x, R_Ω at (x, Ω) and factors the bordered matrix with last row `t`.
    /// Returns the relative residual, or None if singular.
    pub(super) fn factor(
        &mut self,
        hb: &mut HarmonicBalance,
        ws: &mut Workspace,
        x: &[f64],
        omega: f64,
        t: &[f64],
        sc: Scales,
    ) -> Result<Option<f64>> {
        let Scales { sx, so, ext } = sc;
        if (hb.basis().omega() - omega).abs() > 0.0 {
            hb.set_omega(omega)?;
        }
        hb.residual_real_into(x, &mut self.r, Some(&mut self.jac), ws)?;
        let rel = self.relative_residual(ext)?;
        hb.omega_derivative_real_into(x, &mut self.r_omega, ws)?;
        let m = self.layout.len();
        for (j, tj) in t.iter().enumerate().take(m) {
            for i in 0..m {
                self.big[(i, j)] = self.jac[(i, j)] * sx;
            }
            self.big[(m, j)] = *tj;
        }
        for i in 0..m {
            self.big[(i, m)] = self.r_omega[i] * so;
        }
        self.big[(m, m)] = t[m];
        Ok(lu::factor_in_place(&mut self.big, &mut self.perm).then_some(rel))
    }

    /// `‖R‖ / ext` of the residual in `r`; an error if it is not finite.
    fn relative_residual(&self, ext: f64) -> Result<f64> {
        let rel = self.layout.norm(&self.r) / ext;
        if !rel.is_finite() {
            return Err(Error::NonFinite {
                what: "residual on the branch".into(),
            });
        }
        Ok(rel)
    }

    /// Solves the factored bordered system in place (`rhs` in, solution out).
    pub(super) fn solve(&self, rhs: &mut [f64]) {
        lu::solve_in_place(&self.big, &self.perm, rhs);
    }
}

/// A corrector target: the predicted point `(x_p, Ω_p)` and the last row `t` of the bordered
/// system (the tangent for a pseudo-arclength step, `e_Ω` to land on a given Ω).
pub(super) struct Target<'a> {
    pub(super) xp: &'a [f64],
    pub(super) op: f64,
    pub(super) row: &'a [f64],
    /// Whether this is a sweep's step: Ω is kept from the first iterate near the branch on,
    /// and the steps at fixed Ω may reuse the factors ([`Continuation::correct`]), for a
    /// caller that needs the tangent at the result only as a predictor.
    pub(super) chord: bool,
}

/// The scales of the unknowns: `s_x` (the RMS of the current point) and `s_Ω`.
#[derive(Clone, Copy)]
pub(super) struct Scales {
    pub(super) sx: f64,
    pub(super) so: f64,
    pub(super) ext: f64,
}

impl Scales {
    /// Scales `s_x`, `s_Ω` and the residual norm `ext` that residuals are relative to.
    pub(super) fn new(sx: f64, so: f64, ext: f64) -> Self {
        Self { sx, so, ext }
    }

    /// The predictor `(x, Ω) + s t` in the scaled unknowns: writes `x_p`, returns `Ω_p`.
    pub(super) fn predict(&self, x: &[f64], omega: f64, t: &[f64], s: f64, xp: &mut [f64]) -> f64 {
        let m = x.len();
        for i in 0..m {
            xp[i] = x[i] + s * t[i] * self.sx;
        }
        omega + s * t[m] * self.so
    }
}

/// The discretised problem at the current Ω with the corrector's buffers and scales.
pub(super) struct Tracer<'m> {
    pub(super) hb: HarmonicBalance<'m>,
    pub(super) ws: Workspace,
    pub(super) b: Bordered,
    pub(super) sc: Scales,
}

impl<'m> Tracer<'m> {
    /// The tracer of `hb` with scales `sc`.
    pub(super) fn new(hb: HarmonicBalance<'m>, sc: Scales) -> Self {
        let ws = hb.workspace();
        let b = Bordered::new(hb.layout());
        Self { hb, ws, b, sc }
    }

    /// Factors the bordered matrix with last row `row` at `(x, Ω)`: the relative residual, or
    /// `None` if singular.
    pub(super) fn factor(&mut self, x: &[f64], omega: f64, row: &[f64]) -> Result<Option<f64>> {
        self.b
            .factor(&mut self.hb, &mut self.ws, x, omega, row, self.sc)
    }

    /// The relative residual at `x` (the current Ω), into the buffer `b.r`; no Jacobian.
    pub(super) fn residual(&mut self, x: &[f64]) -> Result<f64> {
        self.hb
            .residual_real_into(x, &mut self.b.r, None, &mut self.ws)?;
        self.b.relative_residual(self.sc.ext)
    }

    /// The norm residuals are relative to: the load's (or the load of the split, or 1 without
    /// either).
    pub(super) fn load_norm(&self) -> f64 {
        let hb = &self.hb;
        [hb.norm(hb.external_load()), hb.norm(hb.split_load()), 1.0]
            .into_iter()
            .find(|v| *v > 0.0)
            .unwrap_or(1.0)
    }

    /// The RMS of `x` (bounded below relative to the load): the scale `s_x` of a point.
    pub(super) fn rms(&self, x: &[f64]) -> f64 {
        let norm = self.hb.layout().norm(x);
        (norm / (x.len() as f64).sqrt()).max(1e-12 * self.sc.ext.max(1.0))
    }

    /// The unit chord from `(x, Ω)` to `(x', Ω')` in the scaled unknowns, and its length.
    pub(super) fn chord(&self, x: &[f64], omega: f64, x2: &[f64], omega2: f64) -> (Vec<f64>, f64) {
        let sc = self.sc;
        let h = self.distance(x2, omega2, x, omega);
        let mut t: Vec<f64> = x.iter().zip(x2).map(|(a, b)| (b - a) / sc.sx / h).collect();
        t.push((omega2 - omega) / sc.so / h);
        (t, h)
    }

    /// The scaled distance between `(x, Ω)` and `(x', Ω')`.
    pub(super) fn distance(&self, x: &[f64], omega: f64, x2: &[f64], omega2: f64) -> f64 {
        let sc = self.sc;
        (x.iter()
            .zip(x2)
            .map(|(a, b)| ((a - b) / sc.sx).powi(2))
            .sum::<f64>()
            + ((omega - omega2) / sc.so).powi(2))
        .sqrt()
    }
}

impl Continuation {
    /// Newton on the bordered system towards `target`, from `(x, Ω)`; on success the number
    /// of iterations and the relative residual. The matrix is then factored at the result, or
    /// with [`Target::chord`] possibly at the iterate where Ω was fixed (chord steps).
    ///
    /// Once an iteration keeps Ω ([`hold_omega`]), the next steps are Newton steps at that
    /// fixed Ω. With [`Target::chord`] they reuse the factors (chord steps: a residual without
    /// the Jacobian, no factorisation) while each one reduces the residual at least
    /// [`CHORD_RATE`]-fold, and otherwise factor the Jacobian at the iterate again.
    pub(super) fn correct(
        &self,
        tr: &mut Tracer,
        x: &mut [f64],
        o: &mut f64,
        target: &Target,
    ) -> Option<(usize, f64)> {
        let m = x.len();
        let sc = tr.sc;
        let (mut held, mut last) = (false, f64::INFINITY);
        for it in 0..=self.max_corrector {
            if !(*o > 0.0 && o.is_finite()) {
                return None;
            }
            let mut rel = None;
            if held && target.chord {
                let chord = tr.residual(x).ok()?;
                if chord <= self.tolerance {
                    return Some((it, chord));
                }
                if chord <= CHORD_RATE * last {
                    rel = Some(chord);
                }
            }
            let rel = match rel {
                Some(rel) => rel,
                None => {
                    let factored = tr.b.factor(&mut tr.hb, &mut tr.ws, x, *o, target.row, sc);
                    match factored {
                        Ok(Some(rel)) => rel,
                        Ok(None) | Err(_) => return None,
                    }
                }
            };
            if rel <= self.tolerance {
                return Some((it, rel));
            }
            if it == self.max_corrector {
                return None;
            }
            // δ from [R; rowᵀ(y - y_p)].
            let b = &mut tr.b;
            let mut g = 0.0;
            for i in 0..m {
                g += target.row[i] * (x[i] - target.xp[i]) / sc.sx;
                b.rhs[i] = -b.r[i];
            }
            g += target.row[m] * (*o - target.op) / sc.so;
            b.rhs[m] = -g;
            lu::solve_in_place(&b.big, &b.perm, &mut b.rhs);
            // The sweep's steps keep Ω as soon as the iterate is near the branch; the others
            // (branch switching, turning points, the landing) after a first full step.
            let near = if target.chord {
                rel <= HOLD_OMEGA_RESIDUAL
            } else {
                it >= 1 && rel <= HOLD_OMEGA_RESIDUAL_LATE
            };
            held = near && hold_omega(b);
            last = rel;
            for i in 0..m {
                x[i] += b.rhs[i] * sc.sx;
            }
            *o += b.rhs[m] * sc.so;
        }
        None
    }

    /// The Ω of the turning point between the point `(x, Ω)` (arclength 0, tangent `t0`) and
    /// the next one: the secant method on the tangent's Ω component `t_Ω(s)` along the
    /// predictor line `s ↦ (x, Ω) + s t0`, each `s` corrected onto the branch (hyperplane
    /// normal `t0`). Stops when `|t_Ω| < 1e-12` or the bracket is below 1e-12 of the step.
    pub(super) fn locate_turn(
        &self,
        tr: &mut Tracer,
        x: &[f64],
        omega: f64,
        t0: &[f64],
        ends: [(f64, f64); 2],
    ) -> Option<f64> {
        let m = x.len();
        let [(mut s0, mut f0), (mut s1, mut f1)] = ends;
        let (mut xp, mut xc, mut tt) = (vec![0.0; m], vec![0.0; m], vec![0.0; m + 1]);
        let mut best = None;
        for _ in 0..30 {
            if f1 == f0 {
                break;
            }
            let s = s1 - f1 * (s1 - s0) / (f1 - f0);
            if !s.is_finite() {
                break;
            }
            let op = tr.sc.predict(x, omega, t0, s, &mut xp);
            xc.copy_from_slice(&xp);
            let mut oc = op;
            let target = Target {
                xp: &xp,
                op,
                row: t0,
                chord: false,
            };
            self.correct(tr, &mut xc, &mut oc, &target)?;
            tangent(&mut tr.b, &mut tt);
            best = Some(oc);
            if tt[m].abs() < 1e-12 || (s - s1).abs() < 1e-12 * ends[1].0 {
                break;
            }
            (s0, f0, s1, f1) = (s1, f1, s, tt[m]);
        }
        best
    }
}

/// `t ← normalised solution of [[R_x s_x, R_Ω s_Ω], [rowᵀ]] t = (0, 1)` (factored): the unit
/// tangent oriented so that `rowᵀ t > 0`.
pub(super) fn tangent(b: &mut Bordered, t: &mut [f64]) {
    let m = b.layout.len();
    b.rhs.fill(0.0);
    b.rhs[m] = 1.0;
    lu::solve_in_place(&b.big, &b.perm, &mut b.rhs);
    let norm = b.rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
    for (ti, v) in t.iter_mut().zip(&b.rhs) {
        *ti = v / norm;
    }
}

/// The relative residual below which a sweep's corrector iteration keeps Ω ([`hold_omega`]):
/// close enough to the branch that Newton at fixed Ω cannot reach another branch at the same Ω
/// (a fold's other side). A predicted point on a smooth branch is usually that close, so that a
/// point costs one new Ω (in the condensed formulation one refactorisation of every `Z_k`).
const HOLD_OMEGA_RESIDUAL: f64 = 1e-4;

/// The same for the other correctors, from their second iteration on (a branch switch's first
/// iterate must stay on its hyperplane, off the parent branch).
const HOLD_OMEGA_RESIDUAL_LATE: f64 = 1e-6;

/// A chord step at fixed Ω is kept while it reduces the residual at least this much (the
/// factors are from a nearby iterate, so the rate is about the relative change of the
/// Jacobian between them); otherwise the Jacobian is factored again. At this rate a point
/// needs at most 3 chord steps from the hold (1e-4) to the tolerance (1e-10), so that the step
/// control, which counts iterations, sees about Newton's count.
const CHORD_RATE: f64 = 1e-2;

/// Turns the corrector step `δ = B⁻¹ [-R; c]` in `b.rhs` into the step at fixed Ω,
/// `R_x δx = -R`, where the branch is far from a turning point: `δ - (δ_Ω / τ_Ω) τ` with
/// `τ = B⁻¹ [0; 1]` (the same factors), so that `δ_Ω = 0`: the iterate's Ω is kept, and the
/// next iteration needs no new `Z_k` (in the condensed formulation a refactorisation of every
/// harmonic). Near a turning point (`|τ_Ω|` below a quarter of `‖τ‖`) the step stays on the
/// arclength hyperplane. Returns whether Ω was kept.
fn hold_omega(b: &mut Bordered) -> bool {
    let m = b.layout.len();
    let mut tau = vec![0.0; m + 1];
    tau[m] = 1.0;
    lu::solve_in_place(&b.big, &b.perm, &mut tau);
    let norm = tau.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !(tau[m].abs() >= 0.25 * norm && norm.is_finite()) {
        return false;
    }
    let c = b.rhs[m] / tau[m];
    for (d, t) in b.rhs.iter_mut().zip(&tau) {
        *d -= c * t;
    }
    b.rhs[m] = 0.0;
    true
}
