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
pub mod march;
mod packing;

pub use aft::{AftPlan, AftScratch};
pub use basis::HarmonicBasis;
pub(crate) use dynamic_stiffness::non_finite_stiffness;
pub use dynamic_stiffness::{DynamicStiffness, SINGULAR_PIVOT};
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

/// The harmonics `q` (harmonic-major, `n` DOFs) placed on a basis with `h` harmonics whose
/// fundamental is `1/ratio` of theirs: harmonic k becomes harmonic `ratio · k`; the others are
/// zero, and harmonics beyond `h` are dropped. `ratio = 1` pads (or truncates) to `h`; `ratio =
/// 2` embeds a T-periodic orbit in the basis of period 2T ([`HarmonicBasis::doubled`]).
///
/// ```
/// use num_complex::Complex64 as C;
/// let q = [C::new(1.0, 0.0), C::new(2.0, 0.0)];
/// let e = hbal::harmonic::embed(&q, 1, 2, 3);
/// assert_eq!(e, vec![C::new(1.0, 0.0), C::default(), C::new(2.0, 0.0), C::default()]);
/// ```
pub fn embed(q: &[Complex64], n: usize, ratio: usize, h: usize) -> Vec<Complex64> {
    let mut out = vec![Complex64::default(); (h + 1) * n];
    for (k, block) in q.chunks(n).enumerate() {
        let k2 = k * ratio;
        if k2 <= h {
            out[k2 * n..(k2 + 1) * n].copy_from_slice(block);
        }
    }
    out
}
