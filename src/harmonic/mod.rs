//! Harmonic discretisation: the truncated Fourier basis, the alternating frequency/time (AFT)
//! transforms and the per-harmonic dynamic stiffness.
//!
//! Convention: a real periodic signal is stored as complex harmonics `Q_k`, `k = 0..=H`, with
//!
//! `q(θ) = Re Σ_k Q_k e^{ikθ} = a_0 + Σ_{k≥1} a_k cos kθ + b_k sin kθ`, so `Q_0 = a_0`,
//! `Q_k = a_k - i b_k`.
//!
//! Multi-DOF harmonics are stored harmonic-major: `Q[k * n + i]` is DOF `i` at order `k`.

mod aft;
mod basis;
mod dynamic_stiffness;
pub mod kinks;
mod packing;

pub use aft::{AftPlan, AftScratch};
pub use basis::HarmonicBasis;
pub use dynamic_stiffness::DynamicStiffness;
pub use packing::{Part, RealLayout};

use num_complex::Complex64;

/// `(a_k, b_k)` of `a_k cos kθ + b_k sin kθ` from the complex harmonic `Q_k = a_k - i b_k`.
#[inline]
pub fn cos_sin(q: Complex64) -> (f64, f64) {
    (q.re, -q.im)
}

/// The complex harmonic `Q_k = a - i b` of `a cos kθ + b sin kθ`.
#[inline]
pub fn from_cos_sin(a: f64, b: f64) -> Complex64 {
    Complex64::new(a, -b)
}
