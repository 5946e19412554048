//! Which models the exponential flow ([`exponential`](super::exp_flow)) integrates exactly:
//! those whose every law is affine, `f = f0 + k u + d u̇` with constant `(f0, k, d)`, on each
//! piece between its time jumps ([`ForceLaw::time_breakpoints`]) and its kinks
//! ([`ForceLaw::kinks`]).
//!
//! The force-law interface does not say so; it is tested on samples. On every time segment
//! of the law (two angles inside it) and every interval between its kinks (three values of `u`
//! spread over the interval, or over the orbit's amplitude of `u` where the interval is
//! unbounded, and three of `u̇` over the orbit's amplitude of `u̇`) the derivatives must be the
//! same and the force must lie on the plane through the first sample, to 1e-9 relative. A
//! law that passes here and still bends along the orbit is caught by the flow itself, which
//! compares the coefficients at the end of every piece.
//!
//! [`ForceLaw::time_breakpoints`]: crate::force::ForceLaw::time_breakpoints
//! [`ForceLaw::kinks`]: crate::force::ForceLaw::kinks

use crate::force::affine::affine_law;
use crate::model::Model;

/// `true` if every law of `model` is affine on its pieces; `amplitudes[e]` are the largest
/// `|u|` and `|u̇|` of element `e` along the orbit.
pub(crate) fn piecewise_affine(model: &Model, amplitudes: &[(f64, f64)]) -> bool {
    model
        .elements()
        .iter()
        .zip(amplitudes)
        .all(|(e, &(au, adu))| {
            let law = e.law();
            law.is_linear_time_invariant() || (law.memory().is_none() && affine_law(law, au, adu))
        })
}
