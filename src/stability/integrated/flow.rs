//! The flow of the equations of motion and of their variational equation over one period,
//! piece by piece.
//!
//! State `y = (q, q̇, Φ̃)`: the physical state and the scaled monodromy matrix
//! `Φ̃ = S⁻¹ Φ S`, `S = diag(s_q I, s_v I)`, whose entries are of order one. With the
//! time-varying linearisation `K(t) = K + Σ_e k_e(t) w_e w_eᵀ`, `D(t) = D + Σ_e d_e(t) w_e w_eᵀ`
//! (`k_e = ∂f_e/∂u`, `d_e = ∂f_e/∂u̇` along the orbit) and `ω_s = s_v / s_q`,
//!
//! `Φ̃' = [[0, ω_s I], [-M⁻¹K(t)/ω_s, -M⁻¹D(t)]] Φ̃`.
//!
//! **Pieces.** The right-hand side is smooth between the law's declared time jumps
//! ([`ForceLaw::time_breakpoints`](crate::force::ForceLaw::time_breakpoints)) and kinks
//! ([`ForceLaw::kinks`](crate::force::ForceLaw::kinks)). Inside a piece every law is evaluated
//! on its current side of each kink (continued linearly from the one-sided limit where a Runge–
//! Kutta stage strays across), so the integrator sees a smooth field. A crossing of a kink is
//! located to the integrator's accuracy by re-stepping to the crossing time (Newton on
//! `u(t*) = kink`); the piece then changes, and a force that jumps there (contact damping) is
//! accounted for by the saltation matrix
//! `S = I + (F⁺ - F⁻) ∇gᵀ / (∇g·F⁻)`, `g = w·q - kink`, which for `F = (q̇, M⁻¹(...))` adds
//! `-M⁻¹ w Δf (wᵀ δq) / u̇` to `δq̇`. A time jump needs no saltation (its switching surface does
//! not depend on the state).

// Numerical kernels index several arrays in lock step.
#![allow(clippy::needless_range_loop)]

use super::dopri::{step_factor, Stepper};
use super::guide::Guide;
use super::pieces::Pieces;
use crate::error::{Error, Result};
use crate::stability::system::Coordinates;
use nalgebra::{DMatrix, DMatrixView, DMatrixViewMut};

/// The integration options and counters.
pub(crate) struct FlowOptions {
    pub rtol: f64,
    pub h_max: f64,
    pub max_steps: usize,
}

/// The flow over one period.
pub(crate) struct Flow<'c, 'm> {
    sys: &'c Coordinates<'m>,
    n: usize,
    m_inv: DMatrix<f64>,
    omega: f64,
    /// θ bounds of the time pieces over one period.
    bounds: Vec<f64>,
    /// Current time piece: (t_a, θ_a, θ_lo, θ_hi).
    segment: (f64, f64, f64, f64),
    pieces: Pieces,
    scale_q: f64,
    omega_s: f64,
    atol: Vec<f64>,
    /// `M⁻¹K/ω_s`, `M⁻¹D` (row-major) and `M⁻¹w_e` per element.
    base: Vec<f64>,
    mw: Vec<Vec<f64>>,
    // Buffers.
    load: Vec<f64>,
    bc: Vec<f64>,
    /// `(t_b, cos Ωt_b, sin Ωt_b)`: the phasor at the current step start.
    phasor_base: (f64, f64, f64),
    /// The step size at the end of the last period (the next one starts with it).
    h_last: f64,
    /// Steps taken (accepted and rejected).
    pub steps: usize,
    /// The HB orbit the state follows instead of the equations of motion ([`Guide`]).
    guide: Option<Guide>,
}

impl<'c, 'm> Flow<'c, 'm> {
    /// The flow in the coordinates `sys` at fundamental `omega`, with state scales `s_q`, `s_v`.
    pub(crate) fn new(
        sys: &'c Coordinates<'m>,
        omega: f64,
        scale_q: f64,
        scale_v: f64,
        rtol: f64,
    ) -> Result<Self> {
        let model = sys.model;
        let n = sys.len();
        let m_inv = sys
            .mass
            .clone()
            .cholesky()
            .ok_or_else(|| Error::MassNotPositiveDefinite {
                reason: "Cholesky factorisation failed".into(),
            })?
            .inverse();
        let len = 2 * n + 4 * n * n;
        let mut atol = vec![rtol; len];
        atol[..n].iter_mut().for_each(|a| *a = rtol * scale_q);
        atol[n..2 * n].iter_mut().for_each(|a| *a = rtol * scale_v);
        Ok(Self {
            sys,
            n,
            m_inv: m_inv.clone(),
            omega,
            bounds: crate::timesim::segment_bounds(model),
            segment: (0.0, 0.0, 0.0, std::f64::consts::TAU),
            pieces: Pieces::new(sys),
            scale_q,
            omega_s: scale_v / scale_q,
            atol,
            base: {
                let mut b = DMatrix::zeros(n, 2 * n);
                b.columns_mut(0, n)
                    .copy_from(&(&m_inv * &sys.stiffness / (scale_v / scale_q)));
                b.columns_mut(n, n).copy_from(&(&m_inv * &sys.damping));
                b.as_slice().to_vec()
            },
            mw: sys
                .weights
                .iter()
                .map(|w| {
                    (0..n)
                        .map(|i| w.iter().map(|&(j, wj)| m_inv[(i, j)] * wj).sum())
                        .collect()
                })
                .collect(),
            load: vec![0.0; n],
            bc: vec![0.0; 2 * n * n],
            h_last: 0.0,
            phasor_base: (0.0, 1.0, 0.0),
            steps: 0,
            guide: None,
        })
    }

    /// The flow along the HB orbit `guide` (the variational equation about it; the state
    /// `(q, q̇)` must start on it).
    pub(crate) fn along(mut self, guide: Guide) -> Self {
        self.guide = Some(guide);
        self
    }

    fn enter_segment(&mut self, t_a: f64, theta_a: f64, theta_b: f64) {
        let delta = 1e-9 * (theta_b - theta_a);
        self.segment = (t_a, theta_a, theta_a + delta, theta_b - delta);
    }

    /// Force and derivatives of element `e` on its current piece at `(θ, u, u̇)`.
    fn element_law(&self, e: usize, theta: f64, u: f64, du: f64) -> (f64, f64, f64) {
        self.pieces.law(self.sys, e, theta, u, du)
    }

    /// The right-hand side of the augmented state:
    /// `q̈ = M⁻¹(f(θ) - D q̇ - K q - Σ w_e f_e)` and `Φ̃' = Ã(t) Φ̃`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.n;
        let (ta, tha, lo, hi) = self.segment;
        let theta = (tha + self.omega * (t - ta)).clamp(lo, hi);
        let (q, rest) = y.split_at(n);
        let (v, phi) = rest.split_at(n);
        let (dq, rest) = dy.split_at_mut(n);
        let (dv, dphi) = rest.split_at_mut(n);
        dq.copy_from_slice(v);
        self.load.fill(0.0);
        let (c, s) = self.phasor(t);
        self.sys.load_into_phasor(self.omega, c, s, &mut self.load);
        self.bc.copy_from_slice(&self.base);
        // q̈ = M⁻¹ f - (M⁻¹D) q̇ - (M⁻¹K) q, column by column of the column-major base.
        dv.fill(0.0);
        for j in 0..n {
            let (fj, vj, qj) = (self.load[j], v[j], self.omega_s * q[j]);
            let (kc, dc) = (
                &self.base[j * n..(j + 1) * n],
                &self.base[(n + j) * n..(n + j + 1) * n],
            );
            for i in 0..n {
                dv[i] += self.m_inv[(i, j)] * fj - dc[i] * vj - kc[i] * qj;
            }
        }
        let sys = self.sys;
        for ei in 0..sys.weights.len() {
            let (f, ke, de) = self.element_law(ei, theta, sys.gather(ei, q), sys.gather(ei, v));
            let mw = &self.mw[ei];
            let ks = ke / self.omega_s;
            for i in 0..n {
                dv[i] -= f * mw[i];
            }
            if ks != 0.0 || de != 0.0 {
                for &(j, wj) in &sys.weights[ei] {
                    let (kc, dc) = self.bc.split_at_mut((n + j) * n);
                    let (kc, dc) = (&mut kc[j * n..(j + 1) * n], &mut dc[..n]);
                    for i in 0..n {
                        kc[i] += ks * mw[i] * wj;
                        dc[i] += de * mw[i] * wj;
                    }
                }
            }
        }
        if let Some(guide) = &self.guide {
            guide.acceleration_into(t, dv);
        }
        // Φ̃' = [[0, ω_s I], [-(M⁻¹K(t)/ω_s), -M⁻¹D(t)]] Φ̃: the lower block row by one
        // matrix product `-[B C] Φ̃` (n × 2n times 2n × 2n).
        let s2 = 2 * n;
        for c in 0..s2 {
            let (top, bot) = (
                &mut dphi[c * s2..c * s2 + n],
                &phi[c * s2 + n..(c + 1) * s2],
            );
            for i in 0..n {
                top[i] = self.omega_s * bot[i];
            }
        }
        let bc = DMatrixView::from_slice(&self.bc, n, s2);
        let phi_m = DMatrixView::from_slice(phi, s2, s2);
        let mut out = DMatrixViewMut::from_slice_with_strides_mut(&mut dphi[n..], n, s2, 1, s2);
        out.gemm(-1.0, &bc, &phi_m, 0.0);
    }

    /// `(cos Ωt, sin Ωt)` from the phasor at the step start ([`super::dopri::turn`]).
    fn phasor(&self, t: f64) -> (f64, f64) {
        let (tb, cb, sb) = self.phasor_base;
        let (cx, sx) = super::dopri::turn(self.omega * (t - tb));
        (cb * cx - sb * sx, sb * cx + cb * sx)
    }

    /// Moves the phasor base to `t`.
    fn set_phasor_base(&mut self, t: f64) {
        let (s, c) = (self.omega * t).sin_cos();
        self.phasor_base = (t, c, s);
    }

    /// Sets each element's piece from the state `(q, q̇)` at the start.
    fn init_pieces(&mut self, y: &[f64]) {
        let n = self.n;
        self.pieces.init(self.sys, &y[..n], &y[n..2 * n]);
    }

    /// The first kink crossing inside the last step `(t, y) → (t + h, y_new)`: `(fraction of
    /// the step, element, upwards?)` from the cubic Hermite interpolant of each `u`.
    fn first_crossing(
        &self,
        y: &[f64],
        f0: &[f64],
        y1: &[f64],
        f1: &[f64],
        h: f64,
    ) -> Option<(f64, usize, bool)> {
        let n = self.n;
        let mut best: Option<(f64, usize, bool)> = None;
        for ei in 0..self.sys.weights.len() {
            let g = |x: &[f64]| self.sys.gather(ei, &x[..n]);
            let (u0, u1, du0, du1) = (g(y), g(y1), g(f0), g(f1));
            if let Some((s, up)) = self.pieces.crossing(ei, u0, u1, du0, du1, h, self.scale_q) {
                if best.is_none_or(|(sb, _, _)| s < sb) {
                    best = Some((s, ei, up));
                }
            }
        }
        best
    }

    /// Integrates `y` over one period `[0, T]`. `y` must hold `(q, q̇)` and `Φ̃(0)`.
    pub(crate) fn period(
        &mut self,
        y: &mut [f64],
        opts: &FlowOptions,
        stepper: &mut Stepper,
    ) -> Result<()> {
        self.init_pieces(y);
        let bounds = self.bounds.clone();
        let atol = std::mem::take(&mut self.atol);
        let result = self.period_with(y, opts, stepper, &bounds, &atol);
        self.atol = atol;
        let period = std::f64::consts::TAU / self.omega;
        if let Some(guide) = self.guide.as_mut() {
            guide.offset += period;
        }
        result
    }

    fn period_with(
        &mut self,
        y: &mut [f64],
        opts: &FlowOptions,
        stepper: &mut Stepper,
        bounds: &[f64],
        atol: &[f64],
    ) -> Result<()> {
        let n = self.n;
        let omega = self.omega;
        let mut h = if self.h_last > 0.0 {
            self.h_last
        } else {
            opts.h_max.min(0.01 * std::f64::consts::TAU / omega)
        };
        let (mut f0, mut ytmp) = (vec![0.0; y.len()], vec![0.0; y.len()]);
        for w in bounds.windows(2) {
            let (ta, tb) = (w[0] / omega, w[1] / omega);
            self.enter_segment(ta, w[0], w[1]);
            let mut t = ta;
            let mut fresh = true;
            while tb - t > 1e-14 * tb.abs().max(1.0 / omega) {
                if self.steps >= opts.max_steps {
                    return Err(Error::Solver {
                        reason: format!(
                            "Floquet integration needed more than {} steps in one period",
                            opts.max_steps
                        ),
                    });
                }
                self.set_phasor_base(t);
                if fresh {
                    self.rhs(t, y, stepper.start_derivative());
                    fresh = false;
                }
                h = h.min(opts.h_max);
                let last = tb - t <= h * 1.000001;
                let hs = if last { tb - t } else { h };
                self.steps += 1;
                f0.copy_from_slice(stepper.start_derivative());
                let err = stepper.step(
                    &mut |tt, yy, dd| self.rhs(tt, yy, dd),
                    t,
                    y,
                    hs,
                    opts.rtol,
                    atol,
                );
                if !err.is_finite() {
                    return Err(Error::NonFinite {
                        what: format!("variational equation at t = {t:e}"),
                    });
                }
                if err > 1.0 {
                    h = hs * step_factor(err).min(1.0);
                    if h < 1e-14 * (1.0 / omega) {
                        return Err(Error::Solver {
                            reason: format!("Floquet integration step underflow at t = {t:e}"),
                        });
                    }
                    continue;
                }
                let crossing = self.first_crossing(y, &f0, &stepper.y_new, &stepper.f_new, hs);
                let Some((s, e, up)) = crossing else {
                    stepper.advance(y);
                    t += hs;
                    if last {
                        t = tb;
                    }
                    h = hs.max(h.min(hs)) * step_factor(err);
                    if last {
                        h = h.max(hs);
                    }
                    continue;
                };
                // Re-step to the crossing and refine it by Newton on u(t*) = kink.
                let edge = {
                    let (lo, hi) = self.pieces.interval(e);
                    if up {
                        hi
                    } else {
                        lo
                    }
                };
                let sys = self.sys;
                let mut hc = s * hs;
                ytmp.copy_from_slice(y);
                stepper.start_derivative().copy_from_slice(&f0);
                for _ in 0..8 {
                    self.steps += 1;
                    stepper.step(
                        &mut |tt, yy, dd| self.rhs(tt, yy, dd),
                        t,
                        &ytmp,
                        hc,
                        opts.rtol,
                        atol,
                    );
                    let u = sys.gather(e, &stepper.y_new[..n]);
                    let du = sys.gather(e, &stepper.y_new[n..2 * n]);
                    let g = u - edge;
                    if g.abs() <= 1e-14 * (edge.abs() + self.scale_q) || du == 0.0 {
                        break;
                    }
                    hc = (hc - g / du).clamp(1e-3 * hc, hs);
                    stepper.start_derivative().copy_from_slice(&f0);
                }
                stepper.advance(y);
                t += hc;
                self.cross(e, up, t, y);
                fresh = true;
            }
        }
        self.h_last = h;
        Ok(())
    }

    /// Moves element `e` across its kink at time `t` and applies the saltation matrix of a
    /// force jump to `Φ̃` ([`Pieces::cross_with_saltation`]).
    fn cross(&mut self, e: usize, up: bool, t: f64, y: &mut [f64]) {
        let n = self.n;
        let (ta, tha, lo, hi) = self.segment;
        let theta = (tha + self.omega * (t - ta)).clamp(lo, hi);
        let sys = self.sys;
        let (u, du) = (sys.gather(e, &y[..n]), sys.gather(e, &y[n..2 * n]));
        let mw = &self.mw[e];
        let (_, phi) = y.split_at_mut(2 * n);
        self.pieces
            .cross_with_saltation(sys, e, up, (theta, u, du), mw, self.omega_s, phi);
    }
}
