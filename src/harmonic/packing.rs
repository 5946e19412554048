//! Real unknowns for the accelerated solvers: the one place that packs complex harmonics into
//! reals and back.
//!
//! Layout of `x` (length `n (2H+1)`): block 0 holds `a_0` (n DOFs), block `2k-1` holds `a_k` and
//! block `2k` holds `b_k`, where `q = a_0 + Σ a_k cos kθ + b_k sin kθ`. So entry
//! `block(k, part) * n + i` is DOF `i`; see [`RealLayout::block`].

use num_complex::Complex64;

/// Cosine or sine part of a harmonic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// `a_k`, the cosine amplitude.
    Cos,
    /// `b_k`, the sine amplitude.
    Sin,
}

/// The real layout of `n` DOFs times `H` harmonics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RealLayout {
    /// DOFs n.
    pub n: usize,
    /// Harmonics H.
    pub h: usize,
}

impl RealLayout {
    /// Number of real unknowns `n (2H+1)`.
    pub fn len(&self) -> usize {
        self.n * (2 * self.h + 1)
    }

    /// `true` if there are no unknowns.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Block index of harmonic `k`'s part (`k = 0` has only [`Part::Cos`]).
    #[inline]
    pub fn block(k: usize, part: Part) -> usize {
        match (k, part) {
            (0, _) => 0,
            (_, Part::Cos) => 2 * k - 1,
            (_, Part::Sin) => 2 * k,
        }
    }

    /// Parseval weight of block `b`: 1 for the static block, ½ otherwise.
    #[inline]
    pub fn weight(block: usize) -> f64 {
        if block == 0 {
            1.0
        } else {
            0.5
        }
    }

    /// `x ← reals of q` (harmonic-major complex, `Q_k = a_k - i b_k`).
    pub fn pack(&self, q: &[Complex64], x: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            x[i] = q[i].re;
        }
        for k in 1..=self.h {
            for i in 0..n {
                x[(2 * k - 1) * n + i] = q[k * n + i].re;
                x[2 * k * n + i] = -q[k * n + i].im;
            }
        }
    }

    /// `q ← complex harmonics of x`.
    pub fn unpack(&self, x: &[f64], q: &mut [Complex64]) {
        let n = self.n;
        for i in 0..n {
            q[i] = Complex64::new(x[i], 0.0);
        }
        for k in 1..=self.h {
            for i in 0..n {
                q[k * n + i] = Complex64::new(x[(2 * k - 1) * n + i], -x[2 * k * n + i]);
            }
        }
    }

    /// Parseval norm `sqrt(Σ w_b x²)`: the RMS over one period (summed over DOFs), the same as
    /// [`HarmonicBalance::norm`](crate::HarmonicBalance::norm) of the complex form.
    pub fn norm(&self, x: &[f64]) -> f64 {
        let n = self.n;
        let s0: f64 = x[..n].iter().map(|v| v * v).sum();
        let s1: f64 = x[n..].iter().map(|v| v * v).sum();
        (s0 + 0.5 * s1).sqrt()
    }
}
