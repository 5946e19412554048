//! Pseudo-arclength continuation in the speed on the torus (Keller 1977): the branch of
//! `R(U, Ω) = 0` followed through its folds, where a sweep in Ω jumps.
//!
//! With the scaled unknowns `x = (U / s_U, Ω / s_Ω)` and the unit tangent `t`, a step of
//! length `h` predicts `x_p = x + h t` and corrects by Newton on the bordered system
//!
//! `[J  R_Ω s_Ω; t_Uᵀ/s_U  t_Ω] [δU; δw] = −[R; t·(x − x_p)]`,  `δΩ = s_Ω δw`,
//!
//! solved by GMRES (the bordered matrix stays regular at a fold, where `J` is singular), with
//! `R_Ω` by a difference in Ω and the next tangent the secant of the last two points. A
//! corrector that does not converge halves the step; a short one lengthens it.

use super::gmres::gmres;
use super::newton_krylov::{apply_blocks, norm, preconditioner, relative_residual};
use super::{NewtonKrylov, TorusBalance, TorusSolution};
use crate::error::{Error, Result};
use num_complex::Complex64;

/// Arclength settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusArclength {
    /// Newton–Krylov's tolerance of the relative residual, at every point.
    pub tolerance: f64,
    /// First step, in the scaled arclength.
    pub step: f64,
    /// Smallest step before the branch is given up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Most points.
    pub max_points: usize,
    /// Most corrector iterations per point.
    pub max_corrections: usize,
}

impl Default for TorusArclength {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            step: 0.02,
            min_step: 1e-6,
            max_step: 0.1,
            max_points: 2000,
            max_corrections: 8,
        }
    }
}

/// The branch in order along its arclength.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TorusBranch {
    /// The points, each converged.
    pub points: Vec<TorusSolution>,
    /// Turning points passed (the sign of `dΩ` changed).
    pub folds: usize,
    /// Whether the branch reached the end speed.
    pub reached: bool,
    /// Why it stopped short, where it did.
    pub stopped: Option<String>,
}

/// `Σ Re(conj(a) b)`.
fn dot(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.re * y.re + x.im * y.im)
        .sum()
}

fn unknowns(sol: &TorusSolution) -> Vec<Complex64> {
    sol.unknowns
        .iter()
        .map(|&(a, b)| Complex64::new(a, b))
        .collect()
}

impl TorusArclength {
    /// Follows the branch of `hb` from the speed `from` (solved by Newton–Krylov from the
    /// linear response) until it passes `to` (rad/s); `progress` gets the fraction of the
    /// speed range covered. `hb` is left at the last point's speed.
    pub fn run(
        &self,
        hb: &mut TorusBalance,
        from: f64,
        to: f64,
        mut progress: impl FnMut(f64),
    ) -> Result<TorusBranch> {
        if !(from.is_finite() && to.is_finite() && from > 0.0 && to > 0.0 && from != to) {
            return Err(Error::InvalidOptions {
                option: "torus arclength".into(),
                reason: format!("needs two different finite speeds > 0, got {from} and {to}"),
            });
        }
        let newton = NewtonKrylov {
            tolerance: self.tolerance,
            ..NewtonKrylov::default()
        };
        hb.set_omega(from)?;
        let first = newton.solve(hb, None)?;
        if !first.converged {
            return Err(Error::Solver {
                reason: format!("torus arclength: the first point at {from} rad/s did not converge (residual {:.1e})", first.relative_residual),
            });
        }
        let (su, sw) = (norm(&unknowns(&first)).max(1e-300), (to - from).abs());
        let direction = (to - from).signum();
        // The first tangent: dΩ along the range, dU from J dU = −R_Ω dΩ.
        let mut u = unknowns(&first);
        let mut omega = from;
        let r_omega = self.r_omega(hb, &u, omega)?;
        let (ws, blocks) = jacobian_at(hb, &u)?;
        let b: Vec<Complex64> = r_omega.iter().map(|v| -v * direction * sw).collect();
        let mut du = vec![Complex64::default(); u.len()];
        let m = hb.coordinates();
        let ws = std::cell::RefCell::new(ws);
        gmres(
            |v, out| hb.jacobian_apply(v, out, &mut ws.borrow_mut()),
            |v| apply_blocks(&blocks, m, v),
            &b,
            &mut du,
            1e-8,
            120,
            600,
        );
        let mut t = Tangent::new(&du, su, direction);
        let (mut points, mut folds, mut h) = (vec![first], 0, self.step);
        let passed = |w: f64| (w - to) * direction >= 0.0;
        while points.len() < self.max_points {
            let predicted_u: Vec<Complex64> =
                u.iter().zip(&t.u).map(|(x, d)| x + d * (h * su)).collect();
            let predicted_w = omega + h * t.w * sw;
            match self.correct(hb, &t, predicted_u, predicted_w, su, sw)? {
                Some((sol, w, corrections)) => {
                    let new_u = unknowns(&sol);
                    let next = Tangent::secant(&u, &new_u, omega, w, su, sw);
                    if next.w * t.w < 0.0 {
                        folds += 1;
                    }
                    (u, omega, t) = (new_u, w, next);
                    progress(((omega - from) / (to - from)).clamp(0.0, 1.0));
                    points.push(sol);
                    if passed(omega) {
                        return Ok(TorusBranch {
                            points,
                            folds,
                            reached: true,
                            stopped: None,
                        });
                    }
                    if corrections <= 3 {
                        h = (1.5 * h).min(self.max_step);
                    }
                }
                None => {
                    h *= 0.5;
                    if h < self.min_step {
                        let why = format!(
                            "the step fell below {:e} at {omega:.6} rad/s",
                            self.min_step
                        );
                        hb.set_omega(omega)?;
                        return Ok(TorusBranch {
                            points,
                            folds,
                            reached: false,
                            stopped: Some(why),
                        });
                    }
                }
            }
        }
        Ok(TorusBranch {
            points,
            folds,
            reached: false,
            stopped: Some(format!("{} points", self.max_points)),
        })
    }

    /// `∂R/∂Ω` at `(u, omega)` by a forward difference; `hb` is left at `omega` with the
    /// Jacobian's samples of `u`.
    fn r_omega(
        &self,
        hb: &mut TorusBalance,
        u: &[Complex64],
        omega: f64,
    ) -> Result<Vec<Complex64>> {
        let mut ws = hb.workspace();
        let dw = 1e-7 * omega;
        let (mut plus, mut base) = (
            vec![Complex64::default(); u.len()],
            vec![Complex64::default(); u.len()],
        );
        hb.set_omega(omega + dw)?;
        hb.residual_into(u, &mut plus, false, &mut ws)?;
        hb.set_omega(omega)?;
        hb.residual_into(u, &mut base, false, &mut ws)?;
        Ok(plus.iter().zip(&base).map(|(a, b)| (a - b) / dw).collect())
    }

    /// Newton on the bordered system from the prediction `(u, w)`: the converged point, its
    /// speed and the corrections it took, or `None` (the step is to be halved).
    fn correct(
        &self,
        hb: &mut TorusBalance,
        t: &Tangent,
        predicted_u: Vec<Complex64>,
        predicted_w: f64,
        su: f64,
        sw: f64,
    ) -> Result<Option<(TorusSolution, f64, usize)>> {
        let (mut u, mut w) = (predicted_u.clone(), predicted_w);
        let len = u.len();
        for it in 1..=self.max_corrections {
            if !(w.is_finite() && w > 0.0) || hb.set_omega(w).is_err() {
                return Ok(None);
            }
            let r_w = self.r_omega(hb, &u, w)?;
            let mut ws = hb.workspace();
            let mut r = vec![Complex64::default(); len];
            hb.residual_into(&u, &mut r, true, &mut ws)?;
            let relative = relative_residual(hb, &u, &r);
            let du: Vec<Complex64> = u.iter().zip(&predicted_u).map(|(a, b)| a - b).collect();
            let arc = dot(&t.u, &du) / su + t.w * (w - predicted_w) / sw;
            if !relative.is_finite() || relative > 1e6 {
                return Ok(None);
            }
            if relative <= self.tolerance && arc.abs() <= 1e-6 {
                let sol = super::newton_krylov::finish(hb, &u, &mut ws, relative, true, it, 0)?;
                return Ok(Some((sol, w, it)));
            }
            let blocks = preconditioner(hb, &ws);
            let m = hb.coordinates();
            let mut rhs: Vec<Complex64> = r.iter().map(|v| -v).collect();
            rhs.push(Complex64::new(-arc, 0.0));
            let mut step = vec![Complex64::default(); len + 1];
            let ws = std::cell::RefCell::new(ws);
            gmres(
                |v, out| {
                    let (vu, s) = (&v[..len], v[len]);
                    hb.jacobian_apply(vu, &mut out[..len], &mut ws.borrow_mut());
                    for (o, rw) in out[..len].iter_mut().zip(&r_w) {
                        *o += rw * (sw * s.re);
                    }
                    out[len] = Complex64::new(dot(&t.u, vu) / su + t.w * s.re, s.im);
                },
                |v| apply_blocks(&blocks, m, &mut v[..len]),
                &rhs,
                &mut step,
                1e-6,
                120,
                600,
            );
            for (x, d) in u.iter_mut().zip(&step[..len]) {
                *x += d;
            }
            w += sw * step[len].re;
        }
        Ok(None)
    }
}

/// The residual's Jacobian samples and the preconditioner at `u` (`hb` at its speed).
fn jacobian_at(
    hb: &TorusBalance,
    u: &[Complex64],
) -> Result<(super::TorusWorkspace, Vec<nalgebra::DMatrix<Complex64>>)> {
    let mut ws = hb.workspace();
    let mut r = vec![Complex64::default(); u.len()];
    hb.residual_into(u, &mut r, true, &mut ws)?;
    let blocks = preconditioner(hb, &ws);
    Ok((ws, blocks))
}

/// A unit tangent in the scaled unknowns: `u` (of `U / s_U`) and `w` (of `Ω / s_Ω`).
struct Tangent {
    u: Vec<Complex64>,
    w: f64,
}

impl Tangent {
    /// From `dU` for the scaled speed step `dw`.
    fn new(du: &[Complex64], su: f64, dw: f64) -> Self {
        let u: Vec<Complex64> = du.iter().map(|v| v / su).collect();
        Self::normalised(u, dw)
    }

    /// The secant from `(u0, w0)` to `(u1, w1)`.
    fn secant(u0: &[Complex64], u1: &[Complex64], w0: f64, w1: f64, su: f64, sw: f64) -> Self {
        let u = u1.iter().zip(u0).map(|(a, b)| (a - b) / su).collect();
        Self::normalised(u, (w1 - w0) / sw)
    }

    fn normalised(mut u: Vec<Complex64>, mut w: f64) -> Self {
        let n = (norm(&u).powi(2) + w * w).sqrt().max(1e-300);
        for v in &mut u {
            *v /= n;
        }
        w /= n;
        Self { u, w }
    }
}
