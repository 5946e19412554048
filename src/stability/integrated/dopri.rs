//! The Dormand–Prince 5(4) pair with error control (Dormand & Prince 1980; Hairer, Nørsett,
//! Wanner, *Solving ODEs I*, table II.5.2), the integrator of the variational equation.
//!
//! One step from `(t, y)` with size `h` gives the fifth-order solution
//! `y₁ = y + h Σ b_i k_i` and the error estimate `h Σ e_i k_i` (difference to the embedded
//! fourth-order solution). The caller owns the loop: step-size control, events and restarts.

// Numerical kernels index several arrays in lock step.
#![allow(clippy::needless_range_loop)]

/// Nodes `c_i`.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
/// Coupling coefficients `a_ij` (row i, j < i).
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Fifth-order weights `b_i` (the last row of `A`, `b_7 = 0`: first same as last).
#[cfg(test)]
const B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
/// Error weights `e_i = b_i - b̂_i`.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Stage buffers of one step (no allocation per step).
pub(crate) struct Stepper {
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    /// The fifth-order solution of the last step.
    pub(crate) y_new: Vec<f64>,
    /// `f(t + h, y_new)` of the last step.
    pub(crate) f_new: Vec<f64>,
    err: Vec<f64>,
}

impl Stepper {
    /// Buffers for states of length `len`.
    pub(crate) fn new(len: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; len]),
            stage: vec![0.0; len],
            y_new: vec![0.0; len],
            f_new: vec![0.0; len],
            err: vec![0.0; len],
        }
    }

    /// `f(t, y)` at the start of the next step, if the caller already has it (first same as
    /// last); otherwise [`Stepper::step`] evaluates it.
    pub(crate) fn start_derivative(&mut self) -> &mut [f64] {
        &mut self.k[0]
    }

    /// One step of size `h` from `(t, y)`, with `k_1 = f(t, y)` already in
    /// [`Stepper::start_derivative`]. Returns the error norm
    /// `sqrt(mean((err_i / (atol_i + rtol max(|y_i|, |y_new_i|)))²))`; the step is acceptable
    /// when it is at most 1.
    pub(crate) fn step(
        &mut self,
        f: &mut impl FnMut(f64, &[f64], &mut [f64]),
        t: f64,
        y: &[f64],
        h: f64,
        rtol: f64,
        atol: &[f64],
    ) -> f64 {
        let len = y.len();
        for s in 1..7 {
            for i in 0..len {
                let mut acc = 0.0;
                for (j, a) in A[s][..s].iter().enumerate() {
                    acc += a * self.k[j][i];
                }
                self.stage[i] = y[i] + h * acc;
            }
            let (done, rest) = self.k.split_at_mut(s);
            let _ = done;
            f(t + C[s] * h, &self.stage, &mut rest[0]);
        }
        // Stage 7 sits at y_new (first same as last).
        self.y_new.copy_from_slice(&self.stage);
        self.f_new.copy_from_slice(&self.k[6]);
        let mut sum = 0.0;
        for i in 0..len {
            let mut e = 0.0;
            for (s, ei) in E.iter().enumerate() {
                e += ei * self.k[s][i];
            }
            self.err[i] = h * e;
            let scale = atol[i] + rtol * y[i].abs().max(self.y_new[i].abs());
            sum += (self.err[i] / scale).powi(2);
        }
        (sum / len as f64).sqrt()
    }

    /// Makes the end of the last step the start of the next: `k_1 = f_new`.
    pub(crate) fn advance(&mut self, y: &mut [f64]) {
        y.copy_from_slice(&self.y_new);
        self.k[0].copy_from_slice(&self.f_new);
    }
}

/// The step-size factor after a step with error norm `err` (order 5, safety 0.9, within
/// `[0.2, 5]`).
pub(crate) fn step_factor(err: f64) -> f64 {
    if err == 0.0 {
        5.0
    } else {
        (0.9 * err.powf(-0.2)).clamp(0.2, 5.0)
    }
}

/// `(cos x, sin x)` by a short Taylor series for `|x| <= 1/4` (terms up to x¹³/13!, below
/// 3e-16; the flows turn a phasor by at most one step), `sin_cos` further away.
pub(crate) fn turn(x: f64) -> (f64, f64) {
    if x.abs() > 0.25 {
        let (s, c) = x.sin_cos();
        return (c, s);
    }
    // Horner form of 1 - x²/2! + … and x - x³/3! + ….
    let x2 = x * x;
    let (mut c, mut s) = (1.0, 1.0);
    for k in (1..=6).rev() {
        let k = k as f64;
        c = 1.0 - x2 / ((2.0 * k - 1.0) * (2.0 * k)) * c;
        s = 1.0 - x2 / ((2.0 * k) * (2.0 * k + 1.0)) * s;
    }
    (c, x * s)
}

/// The cubic Hermite interpolant on a step: the value at fraction `s ∈ [0, 1]` of a scalar
/// with values `u0`, `u1` and derivatives `du0`, `du1` (per unit time) over a step `h`.
pub(crate) fn hermite(u0: f64, u1: f64, du0: f64, du1: f64, h: f64, s: f64) -> f64 {
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * u0
        + (s3 - 2.0 * s2 + s) * h * du0
        + (-2.0 * s3 + 3.0 * s2) * u1
        + (s3 - s2) * h * du1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tableau_satisfies_the_order_conditions() {
        for (ci, row) in C.iter().zip(&A) {
            assert!((row.iter().sum::<f64>() - ci).abs() < 1e-14);
        }
        // Σ b c^q = 1/(q+1), q = 0..4 (the bushy-tree conditions up to order 5).
        for q in 0..5 {
            let s: f64 = B.iter().zip(&C).map(|(b, c)| b * c.powi(q)).sum();
            assert!((s - 1.0 / (q as f64 + 1.0)).abs() < 1e-14, "q = {q}: {s}");
        }
        assert!(E.iter().sum::<f64>().abs() < 1e-15);
        // The embedded solution is order 4, not 5: Σ b̂ c⁴ ≠ 1/5.
        let s: f64 = B
            .iter()
            .zip(&E)
            .zip(&C)
            .map(|((b, e), c)| (b - e) * c.powi(4))
            .sum();
        assert!((s - 0.2).abs() > 1e-5);
    }

    #[test]
    fn fixed_steps_converge_with_order_five() {
        // y'' = -y (y = cos t) over [0, 2π] with fixed steps.
        let run = |steps: usize| {
            let h = std::f64::consts::TAU / steps as f64;
            let mut st = Stepper::new(2);
            let mut f = |_t: f64, y: &[f64], dy: &mut [f64]| {
                dy[0] = y[1];
                dy[1] = -y[0];
            };
            let mut y = vec![1.0, 0.0];
            f(0.0, &y, st.start_derivative());
            for i in 0..steps {
                st.step(&mut f, i as f64 * h, &y, h, 1.0, &[1.0, 1.0]);
                st.advance(&mut y);
            }
            (y[0] - 1.0).abs().max(y[1].abs())
        };
        let (e1, e2) = (run(40), run(80));
        let order = (e1 / e2).log2();
        assert!(
            (order - 5.0).abs() < 0.3,
            "observed order {order} ({e1:e}, {e2:e})"
        );
    }

    #[test]
    fn turn_matches_sin_cos() {
        for x in [-0.25, -0.1, 0.0, 1e-3, 0.17, 0.25, 0.3, 2.0] {
            let (c, s) = turn(x);
            assert!(
                (c - x.cos()).abs() < 3e-16 && (s - x.sin()).abs() < 3e-16,
                "{x}"
            );
        }
    }

    #[test]
    fn hermite_is_exact_for_cubics() {
        let p = |t: f64| 1.0 + 2.0 * t - t * t + 0.5 * t * t * t;
        let dp = |t: f64| 2.0 - 2.0 * t + 1.5 * t * t;
        let (t0, h) = (0.3, 0.7);
        let v = hermite(p(t0), p(t0 + h), dp(t0), dp(t0 + h), h, 0.4);
        assert!((v - p(t0 + 0.4 * h)).abs() < 1e-14);
    }
}
