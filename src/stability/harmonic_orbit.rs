//! The monodromy matrix along the HB orbit itself ([`Orbit::Harmonic`](super::Orbit::Harmonic)):
//! the exponential flow's pieces without integrating the orbit.
//!
//! Where every law is affine between its time jumps and kinks ([`exponential`](super::exponential::exp_flow)),
//! the variational equation `Φ̃' = Ã(t) Φ̃` depends on the orbit only through the piece each
//! element is in. Along the HB orbit `q_H(t) = Re Σ_k Q_k e^{ikωt}` the element coordinates
//! `u_e(t) = w_e·q_H(t)` are trigonometric polynomials, so the pieces are known without a
//! step of integration: a kink `κ` is crossed at a root of `u_e(θ) − κ` (`θ = ωt`), found on
//! `16H` samples (a power of two, at least 64) and refined by safeguarded Newton with the
//! analytic derivative. `Φ̃` is then the same product as for an integrated orbit
//! ([`record`](super::exponential::record)): per piece `E_δ₀^m e^{Ãτ}` with `h = m δ₀ + τ`, per crossing the
//! saltation matrix of a force jump, from `u̇_e` at the root.
//!
//! What it saves: the orbit's sub-steps (the drivetrain's ~9,000 per period at its contact
//! modes' 70,000 rad/s, each a product with `E_δ₀` and a look for crossings) and the load's
//! part `X_δ₀` of every generator. What it gives: the multipliers of the linearisation along
//! the HB solution, as Hill's method does, so their error is the HB solution's (the crossing
//! times move by `δu/u̇`). A pair of crossings closer than a sample spacing on the same side of
//! the samples is not seen; its piece is shorter than the spacing `2π/(16Hω)` and grazes the
//! kink by less than `⅛ δθ² max|u''|`.

use super::exponential::exp_flow::ExpFlow;
use super::exponential::record::Step;
use crate::error::{Error, Result};
use crate::harmonic::kinks::{bracketed_newton, derivatives};
use crate::harmonic::{AftPlan, HarmonicBasis};
use crate::model::Model;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// A root of `u_e(θ) − κ`.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    /// The phase `θ = ωt` in `[0, 2π)`.
    theta: f64,
    element: usize,
    kink: f64,
    up: bool,
    /// `du_e/dθ` there.
    slope: f64,
}

impl ExpFlow<'_, '_> {
    /// Appends to `record` the pieces of the HB orbit with harmonics `harmonics` (the model's
    /// DOFs, harmonic-major, `0..=H`) and fundamental `fundamental` over its period (`periods`
    /// periods of the flow's Ω). The element coordinates are the model's, not their projection
    /// onto a reduced basis: the pieces are the HB solution's, whatever the basis. At the
    /// end of every piece each law is evaluated at the HB orbit: `Ok(false)` if one is not
    /// affine on its piece after all (as the integrated flow checks), and `record` is then
    /// meaningless.
    pub(crate) fn along_harmonics(
        &mut self,
        harmonics: &[Complex64],
        fundamental: f64,
        periods: usize,
        record: &mut Vec<Step>,
    ) -> Result<bool> {
        self.monodromy_only = true;
        record.clear();
        self.begin_pass();
        let crossings = self.crossings(harmonics, fundamental)?;
        let coordinates = element_harmonics(self.sys.model, harmonics);
        let (omega, delta0) = (self.omega, self.delta0);
        let bounds = self.bounds.clone();
        let mut next = crossings.iter().peekable();
        let windows = bounds.len() - 1;
        for p in 0..periods {
            let offset = p as f64 * TAU / omega;
            for (i, w) in bounds.windows(2).enumerate() {
                let (ta, tb) = (offset + w[0] / omega, offset + w[1] / omega);
                // The last window takes every event left: a root within rounding of 2π may
                // map to a time at or past its end.
                let last = p + 1 == periods && i + 1 == windows;
                let margin = 1e-9 * (w[1] - w[0]);
                let angle = |t: f64| (w[0] + omega * (t - ta)).clamp(w[0] + margin, w[1] - margin);
                let mut t = ta;
                loop {
                    let event = next.next_if(|c| last || c.theta / fundamental < tb);
                    let end = event.map_or(tb, |c| (c.theta / fundamental).clamp(t, tb));
                    if end > t {
                        let piece = self.piece(angle(0.5 * (t + end)));
                        let whole = ((end - t) / delta0).floor();
                        let tau = (end - t - whole * delta0).max(0.0);
                        self.steps += 1;
                        let step = Step::Piece {
                            state: piece.state,
                            whole: whole as usize,
                            tau,
                        };
                        self.emit(record, step);
                        let theta = (end * fundamental).rem_euclid(TAU);
                        let hb = |e: usize| {
                            let d = derivatives(&coordinates[e], theta);
                            (d[0], d[1] * fundamental)
                        };
                        if !self.coefficients_hold(&piece, angle(end), hb) {
                            return Ok(false);
                        }
                    }
                    t = end;
                    let Some(c) = event else { break };
                    // Cross from the side below (above) the kink: where the samples and the
                    // state at t = 0 disagree (a root on the kink at t = 0), the samples win.
                    let (lo, hi) = self.pieces.interval(c.element);
                    if (c.up && hi != c.kink) || (!c.up && lo != c.kink) {
                        self.pieces.place(c.element, c.kink, !c.up);
                    }
                    let du = c.slope * fundamental;
                    let omega_s = self.scale_v / self.scale_q;
                    let at = (angle(t), c.kink, du);
                    if let Some(factor) = self
                        .pieces
                        .cross_jump(self.sys, c.element, c.up, at, omega_s)
                    {
                        let jump = Step::Jump {
                            element: c.element,
                            factor,
                        };
                        self.emit(record, jump);
                    }
                }
            }
        }
        self.end_pass();
        Ok(true)
    }

    /// Back to integrating orbits after [`ExpFlow::along_harmonics`] gave up: the generators'
    /// states without the load's part are dropped (their cores stay kept).
    pub(crate) fn integrate_from_here(&mut self) {
        self.monodromy_only = false;
        self.states.clear();
        self.index.clear();
    }

    /// Every kink crossing of the HB orbit over its period, in time order; each kinked
    /// element's piece at `t = 0` set as an integrated orbit would start.
    fn crossings(&mut self, harmonics: &[Complex64], fundamental: f64) -> Result<Vec<Crossing>> {
        let model = self.sys.model;
        let n = model.n_dofs();
        let h = harmonics.len() / n.max(1) - 1;
        let points = (16 * h).next_power_of_two().max(64);
        let plan = AftPlan::new(HarmonicBasis::new(1.0, h)?.with_samples(points)?);
        let mut scratch = plan.make_scratch();
        let mut u = vec![Complex64::default(); h + 1];
        let mut series = vec![0.0; points];
        let mut out = Vec::new();
        for &e in &self.kinks.elements {
            let weights = model.elements()[e].weights();
            for (k, uk) in u.iter_mut().enumerate() {
                *uk = weights.iter().map(|&(i, w)| harmonics[k * n + i] * w).sum();
            }
            let u0: f64 = u.iter().map(|c| c.re).sum();
            let du0: f64 = u.iter().enumerate().map(|(k, c)| -c.im * k as f64).sum();
            self.pieces.init_element(e, u0, du0 * fundamental);
            plan.synthesize_into(&u, |_| Complex64::new(1.0, 0.0), &mut series, &mut scratch);
            if series.iter().any(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "element coordinate of the HB orbit (Floquet analysis)".into(),
                });
            }
            let step = TAU / points as f64;
            for &kink in self.pieces.kinks(e) {
                for j in 0..points {
                    let (a, b) = (series[j] - kink, series[(j + 1) % points] - kink);
                    if (a > 0.0) == (b > 0.0) {
                        continue;
                    }
                    let (theta, slope) = root(&u, kink, j as f64 * step, step, a, b);
                    out.push(Crossing {
                        theta,
                        element: e,
                        kink,
                        up: b > 0.0,
                        slope,
                    });
                }
            }
        }
        out.sort_by(|a, b| a.theta.total_cmp(&b.theta));
        Ok(out)
    }
}

/// The harmonics `U_e,k = w_e·Q_k` of every element's coordinate (`harmonics` in the model's
/// DOFs, harmonic-major).
fn element_harmonics(model: &Model, harmonics: &[Complex64]) -> Vec<Vec<Complex64>> {
    let n = model.n_dofs();
    let h = harmonics.len() / n.max(1);
    model
        .elements()
        .iter()
        .map(|e| {
            (0..h)
                .map(|k| {
                    e.weights()
                        .iter()
                        .map(|&(i, w)| harmonics[k * n + i] * w)
                        .sum()
                })
                .collect()
        })
        .collect()
}

/// The root of `u(θ) − κ` (`u = Re Σ_k U_k e^{ikθ}`) in `[θ₀, θ₀ + δ]`, where it goes from `a`
/// to `b` (opposite signs): safeguarded Newton from the secant's root, bisection where a step
/// leaves the bracket. `(θ*, u'(θ*))`, `θ*` in `[0, 2π)`.
fn root(u: &[Complex64], kink: f64, theta0: f64, delta: f64, a: f64, b: f64) -> (f64, f64) {
    let t = bracketed_newton(
        theta0,
        theta0 + delta,
        theta0 + delta * a / (a - b),
        a > 0.0,
        0.0,
        |t| {
            let d = derivatives(u, t);
            (d[0] - kink, d[1])
        },
    );
    (t.rem_euclid(TAU), derivatives(u, t)[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The roots of `cos θ − 0.3` and their slopes, from samples that miss them.
    #[test]
    fn roots_of_a_trigonometric_polynomial() {
        let u = [Complex64::new(0.0, 0.0), Complex64::new(1.0, 0.0)];
        let step = TAU / 64.0;
        let g = |j: f64| (j * step).cos() - 0.3;
        let (t, s) = root(&u, 0.3, 12.0 * step, step, g(12.0), g(13.0));
        let exact = 0.3f64.acos();
        assert!((t - exact).abs() < 1e-14, "{t} {exact}");
        assert!((s + exact.sin()).abs() < 1e-14);
        // The rising root near 2π comes back in [0, 2π).
        let (t, s) = root(&u, 0.3, 51.0 * step, step, g(51.0), g(52.0));
        assert!((t - (TAU - exact)).abs() < 1e-14, "{t}");
        assert!((s - exact.sin()).abs() < 1e-14);
    }
}
