//! The exact periodic solution in time: the extremes of every DOF, element coordinate and
//! element force, and the elements' mean forces, from the closed form itself rather than from
//! the harmonics `0..=H` (which at low speed lack the ringing of every jump).
//!
//! On a piece the state is `x(t) = x_p(t) + e^{A_p (t - t_p)} h_p` ([module docs](super)).
//! Each piece is cut into intervals of at most 1/32 of the fastest natural period (the
//! estimate `ω_s`); at their ends the free motion is stepped by one exponential `e^{A_p δ}`
//! and `q`, `q̇`, `q̈`, `q⃛` come exactly from the state (`q̈_f = -M⁻¹(K q_f + D q̇_f)`, the
//! steady part from its harmonics). A signal `g` (a DOF, `u = w·q`, or the force
//! `k u + d u̇ + f_0` of the piece's coefficients) is known there with `g'` and `g''`; between
//! two ends the quintic Hermite interpolant (error `O(δ⁶ g⁽⁶⁾)`, about 1e-9 of the ringing's
//! amplitude at 32 intervals per period) locates an interior extremum where `g'` changes
//! sign. A force that jumps at a piece's end is evaluated on both sides of it. The mean forces
//! come from the closed form's integral over each piece: `∫ q dt` is the steady part's
//! `Re Σ_k Q_k (e^{ikb} - e^{ika}) / (ikΩ)` plus the free motion's
//! `-K_p⁻¹ (M Δq̇_f + D_p Δq_f)` (the equation of motion integrated over the piece), and
//! `∫ u̇ dt = u(b) - u(a)`; exact whatever the intervals.

use super::schedule::{Configuration, Schedule};
use crate::stability::expm::ExpWork;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// Intervals per fastest natural period.
const PER_PERIOD: f64 = 32.0;
/// At least this many intervals per piece.
const MIN_PER_PIECE: usize = 8;
/// Work budget (about `intervals × 12 n²` operations); beyond it the intervals grow, and the
/// extremes between grid points lose accuracy (the grid values stay exact).
const WORK: f64 = 4e8;

/// The smallest and largest value of a signal over the period.
pub type Range = (f64, f64);

/// An element's extremes and mean force over the exact periodic solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElementExtremes {
    /// `(min, max)` of its coordinate `u = w·q`.
    pub coordinate: Range,
    /// `(min, max)` of its force `f(θ, u, u̇)`, both sides of every jump included.
    pub force: Range,
    /// The force's mean over the period.
    pub force_mean: f64,
}

/// The extremes of the exact periodic solution ([module docs](crate::solve::piecewise::waveform)).
#[derive(Debug, Clone, PartialEq)]
pub struct ExactExtremes {
    /// `(min, max)` of every DOF.
    pub dofs: Vec<Range>,
    /// Every element of the model, in its order.
    pub elements: Vec<ElementExtremes>,
    /// Intervals the period was cut into.
    pub intervals: usize,
    /// `false` where the work budget (large models) left fewer than 32 intervals per period
    /// of the fastest motion: the extremes between the grid's points are then approximate
    /// (the mean forces stay exact).
    pub resolved: bool,
}

impl ExactExtremes {
    /// `max |q_i|` of every DOF.
    pub fn max_abs(&self) -> Vec<f64> {
        self.dofs
            .iter()
            .map(|(lo, hi)| lo.abs().max(hi.abs()))
            .collect()
    }
}

/// The schedule and the free motion at every piece's start: all that is needed to evaluate
/// the exact solution anywhere.
pub(super) struct Waveform {
    pub(super) schedule: Schedule,
    /// `h_p` in `(q, q̇)`.
    pub(super) free_start: Vec<DVector<f64>>,
    /// `Φ_p h_p`, the free motion at the piece's end.
    pub(super) free_end: Vec<DVector<f64>>,
    /// Every element's weights `w` (`u = w·q`).
    pub(super) weights: Vec<Vec<(usize, f64)>>,
}

impl std::fmt::Debug for Waveform {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Waveform")
            .field("pieces", &self.schedule.pieces.len())
            .field("configurations", &self.schedule.configurations.len())
            .finish()
    }
}

/// `(g, g', g'')` of every tracked signal at one time.
type Jets = Vec<[f64; 3]>;

/// A signal's running extremes.
#[derive(Clone, Copy)]
struct Tracker {
    min: f64,
    max: f64,
}

impl Tracker {
    fn see(&mut self, v: f64) {
        self.min = self.min.min(v);
        self.max = self.max.max(v);
    }

    /// Whether the quintic between `a` and `b` can leave the range seen so far: it lies
    /// within `[min(g_0, g_1) - B, max(g_0, g_1) + B]`,
    /// `B = 0.25 δ (|g'_0| + |g'_1|) + 0.03 δ² (|g''_0| + |g''_1|)` (the largest moduli of its
    /// Hermite basis functions on [0, 1] are 0.2 and 0.02). Flat stretches, where `g'` changes
    /// sign at rounding level, are skipped.
    fn may_extend(&self, a: &[f64; 3], b: &[f64; 3], dt: f64) -> bool {
        let bound =
            0.25 * dt * (a[1].abs() + b[1].abs()) + 0.03 * dt * dt * (a[2].abs() + b[2].abs());
        a[0].max(b[0]) + bound > self.max || a[0].min(b[0]) - bound < self.min
    }
}

impl Waveform {
    /// The fastest motion's angular frequency: the highest natural frequency's estimate or
    /// the highest load order's.
    pub(super) fn fastest(&self) -> f64 {
        let s = &self.schedule;
        s.highest_frequency()
            .max(s.model_load_orders as f64 * s.omega)
    }

    /// Every element's mean force `(1/T) Σ_p ∫ (k_e u + d_e u̇ + f_e) dt`, exactly: on a
    /// piece `∫ q dt` is the steady part's `Re Σ_k Q_k (e^{ikb} - e^{ika}) / (ikΩ)` (`Q_0 τ`)
    /// plus the free motion's `-K_p⁻¹ (M Δq̇_f + D_p Δq_f)` (the equation of motion
    /// integrated over the piece), and `∫ u̇ dt = u(b) - u(a)`.
    fn mean_forces(&self) -> Vec<f64> {
        let s = &self.schedule;
        let (n, omega) = (s.n, s.omega);
        let stiffness: Vec<_> = s
            .configurations
            .iter()
            .map(|c| c.stiffness.clone().lu())
            .collect();
        let mut sums = vec![0.0; self.weights.len()];
        for ((piece, h), e) in s.pieces.iter().zip(&self.free_start).zip(&self.free_end) {
            let config = &s.configurations[piece.configuration];
            let (a, b) = (piece.start, piece.end);
            let delta = e - h;
            let rhs = &s.mass * delta.rows(n, n) + &config.damping * delta.rows(0, n);
            let free = stiffness[piece.configuration]
                .solve(&rhs)
                .unwrap_or_else(|| DVector::zeros(n));
            let integral = config.steady_integral(a, b, omega) - free;
            let change = config.steady_state(b, omega).rows(0, n)
                - config.steady_state(a, omega).rows(0, n)
                + delta.rows(0, n);
            for ((sum, w), &(k, d, f0)) in sums.iter_mut().zip(&self.weights).zip(&config.elements)
            {
                *sum +=
                    k * gather(w, &integral) + d * gather(w, &change) + f0 * piece.duration(omega);
            }
        }
        let period = TAU / omega;
        sums.iter().map(|v| v / period).collect()
    }

    /// The extremes and mean forces over the period.
    pub(super) fn extremes(&self) -> ExactExtremes {
        let s = &self.schedule;
        let (n, omega) = (s.n, s.omega);
        let m = self.weights.len();
        let signals = n + 2 * m;
        let mut track = vec![
            Tracker {
                min: f64::INFINITY,
                max: f64::NEG_INFINITY
            };
            signals
        ];
        // Intervals per second: PER_PERIOD per period of the fastest motion (the highest
        // natural frequency or the highest load order), within the work budget.
        let period = TAU / omega;
        let wanted = PER_PERIOD * self.fastest() / TAU;
        let affordable = WORK / (12.0 * (n * n) as f64 * period);
        let rate = wanted.min(affordable);
        let mut work = ExpWork::new(2 * n);
        let mut step = DMatrix::zeros(2 * n, 2 * n);
        let mut buffers = JetBuffers::new(n, m);
        let mut total = 0;
        for (piece, h) in s.pieces.iter().zip(&self.free_start) {
            let config = &s.configurations[piece.configuration];
            let tau = piece.duration(omega);
            let intervals = ((rate * tau).ceil() as usize).max(MIN_PER_PIECE);
            total += intervals;
            let dt = tau / intervals as f64;
            work.exp(&config.generator, dt, &mut step);
            let mut scaled = s.scale_state(h.clone());
            let mut next = DVector::zeros(2 * n);
            for j in 0..=intervals {
                let theta = piece.start + j as f64 * dt * omega;
                buffers.fill(
                    config,
                    &self.weights,
                    theta,
                    omega,
                    &scaled,
                    s.velocity_scale(),
                );
                let jets = &buffers.now;
                for (t, jet) in track.iter_mut().zip(jets) {
                    t.see(jet[0]);
                }
                if j > 0 {
                    let before = &buffers.before;
                    for (t, (a, b)) in track.iter_mut().zip(before.iter().zip(jets)) {
                        if t.may_extend(a, b, dt) {
                            if let Some(v) = interior_extremum(a, b, dt) {
                                t.see(v);
                            }
                        }
                    }
                }
                std::mem::swap(&mut buffers.now, &mut buffers.before);
                if j < intervals {
                    step.mul_to(&scaled, &mut next);
                    std::mem::swap(&mut scaled, &mut next);
                }
            }
        }
        let means = self.mean_forces();
        let range = |t: &Tracker| (t.min, t.max);
        ExactExtremes {
            dofs: track[..n].iter().map(range).collect(),
            elements: (0..m)
                .map(|e| ElementExtremes {
                    coordinate: range(&track[n + e]),
                    force: range(&track[n + m + e]),
                    force_mean: means[e],
                })
                .collect(),
            intervals: total,
            resolved: wanted <= affordable,
        }
    }
}

/// The jets of one interval's two ends and the vectors they are made from, reused.
struct JetBuffers {
    /// `q`, `q̇`, `q̈`, `q⃛` at the current angle.
    derivatives: [DVector<f64>; 4],
    /// `-M⁻¹(K q_f + D q̇_f)` and `-M⁻¹(K q̇_f + D q̈_f)` of the free motion.
    free: [DVector<f64>; 2],
    /// `(g, g', g'')` of every DOF, element coordinate and element force, at the interval's
    /// end and at its start.
    now: Jets,
    before: Jets,
}

impl JetBuffers {
    fn new(n: usize, m: usize) -> Self {
        let zeros = || DVector::zeros(n);
        Self {
            derivatives: [zeros(), zeros(), zeros(), zeros()],
            free: [zeros(), zeros()],
            now: vec![[0.0; 3]; n + 2 * m],
            before: vec![[0.0; 3]; n + 2 * m],
        }
    }

    /// `now` at angle `θ` with the free motion `scaled = (q_f, q̇_f/ω_s)` on `config`.
    fn fill(
        &mut self,
        config: &Configuration,
        weights: &[Vec<(usize, f64)>],
        theta: f64,
        omega: f64,
        scaled: &DVector<f64>,
        velocity_scale: f64,
    ) {
        let n = scaled.len() / 2;
        config.steady_jet_into(theta, omega, &mut self.derivatives);
        let [q, v, a, j] = &mut self.derivatives;
        let [af, jf] = &mut self.free;
        let qf = scaled.rows(0, n);
        let vf = scaled.rows(n, n) * velocity_scale;
        config.mass_stiffness.mul_to(&qf, af);
        af.gemv(1.0, &config.mass_damping, &vf, 1.0);
        af.neg_mut();
        config.mass_stiffness.mul_to(&vf, jf);
        jf.gemv(1.0, &config.mass_damping, af, 1.0);
        jf.neg_mut();
        *q += qf;
        *v += &vf;
        *a += &*af;
        *j += &*jf;
        for (i, out) in self.now[..n].iter_mut().enumerate() {
            *out = [q[i], v[i], a[i]];
        }
        let m = weights.len();
        for (e, (w, &(k, d, f0))) in weights.iter().zip(&config.elements).enumerate() {
            let u = [gather(w, q), gather(w, v), gather(w, a), gather(w, j)];
            self.now[n + e] = [u[0], u[1], u[2]];
            self.now[n + m + e] = [
                k * u[0] + d * u[1] + f0,
                k * u[1] + d * u[2],
                k * u[2] + d * u[3],
            ];
        }
    }
}

/// `u = w·y` of an element with weights `w`.
fn gather(w: &[(usize, f64)], y: &DVector<f64>) -> f64 {
    w.iter().map(|&(i, c)| c * y[i]).sum()
}

/// The value at an interior extremum of the quintic Hermite interpolant between `a` and `b`
/// (`(g, g', g'')` at both ends of an interval of length `dt`), where `g'` changes sign.
fn interior_extremum(a: &[f64; 3], b: &[f64; 3], dt: f64) -> Option<f64> {
    let product = a[1] * b[1];
    if product.is_nan() || product >= 0.0 {
        return None;
    }
    let c = [
        a[0],
        dt * a[1],
        dt * dt * a[2],
        dt * dt * b[2],
        dt * b[1],
        b[0],
    ];
    let slope = |s: f64| {
        let (s2, s3, s4) = (s * s, s * s * s, s * s * s * s);
        c[0] * (-30.0 * s2 + 60.0 * s3 - 30.0 * s4)
            + c[1] * (1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4)
            + c[2] * (s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4)
            + c[3] * (1.5 * s2 - 4.0 * s3 + 2.5 * s4)
            + c[4] * (-12.0 * s2 + 28.0 * s3 - 15.0 * s4)
            + c[5] * (30.0 * s2 - 60.0 * s3 + 30.0 * s4)
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    let rising = c[1] > 0.0;
    for _ in 0..52 {
        let mid = 0.5 * (lo + hi);
        if (slope(mid) > 0.0) == rising {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = 0.5 * (lo + hi);
    let (s2, s3, s4, s5) = (s * s, s * s * s, s.powi(4), s.powi(5));
    let value = c[0] * (1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5)
        + c[1] * (s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5)
        + c[2] * (0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5)
        + c[3] * (0.5 * s3 - s4 + 0.5 * s5)
        + c[4] * (-4.0 * s3 + 7.0 * s4 - 3.0 * s5)
        + c[5] * (10.0 * s3 - 15.0 * s4 + 6.0 * s5);
    Some(value)
}

mod series;
#[cfg(test)]
mod tests;
