//! `offset`: any law on a shifted coordinate, `f = law(θ, u - u0, u̇)`.

use super::memory::{Hysteresis, StepDerivatives};
use super::{ForceLaw, LinearPart};
use crate::error::{check_finite, Result};

/// Samples shifted per block: a stack buffer, so the AFT's batch calls allocate nothing.
const CHUNK: usize = 64;

/// A law acting on the shifted coordinate `u - u0`: `f(θ, u, u̇) = law(θ, u - u0, u̇)`.
///
/// The offset `u0` (metres or radians, as the coordinate) moves the law's origin: a spring
/// mounted with a preload, a stop that sits at `u0` on a shaft whose coordinate is measured from
/// elsewhere. In a scene file every element takes `offset = u0` next to its law's fields; in
/// Rust, wrap the law with [`Offset::new`].
///
/// Everything the law declares moves with it: its linear part
/// `f ≈ f0 + k0 (u - u0) + d0 u̇` becomes the offset `f0 - k0 u0` with the same `(k0, d0)`,
/// its kinks move by `+u0`, its memory (if any) steps on `u - u0`; time variation, band limiting and validation are the law's own. A
/// linear law stays linear time-invariant: the static force `f0 - k0 u0` is a constant load
/// of the split (see [`LinearPart`]).
///
/// ```
/// use hbal::force::{ForceLaw, LinearSpring, Offset};
/// // A spring of 100 N/m with its free length 0.01 m beyond the coordinate's origin.
/// let spring = Offset::new(0.01, LinearSpring::new(100.0, 0.0));
/// assert!((spring.force(0.0, 0.03, 0.0) - 2.0).abs() < 1e-12); // 100 (0.03 - 0.01)
/// assert_eq!(spring.linear_part().offset, -1.0);               // -k u0
/// ```
#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Offset {
    /// The offset u0 (finite), in the unit of the coordinate (m or rad).
    pub offset: f64,
    /// The law on the shifted coordinate.
    pub law: Box<dyn ForceLaw>,
}

impl Offset {
    /// `law` on the coordinate `u - offset`.
    pub fn new(offset: f64, law: impl ForceLaw + 'static) -> Self {
        Self::boxed(offset, Box::new(law))
    }

    /// A boxed `law` (e.g. deserialised from a scene file) on the coordinate `u - offset`.
    pub fn boxed(offset: f64, law: Box<dyn ForceLaw>) -> Self {
        Self { offset, law }
    }

    /// Runs `f` on blocks of at most [`CHUNK`] samples: the block's start, its angles and its
    /// shifted coordinates.
    #[inline]
    fn blocks(&self, theta: &[f64], u: &[f64], mut f: impl FnMut(usize, &[f64], &[f64])) {
        let mut shifted = [0.0; CHUNK];
        for (start, t) in (0..theta.len()).step_by(CHUNK).zip(theta.chunks(CHUNK)) {
            let m = t.len();
            for (s, &x) in shifted[..m].iter_mut().zip(&u[start..start + m]) {
                *s = x - self.offset;
            }
            f(start, t, &shifted[..m]);
        }
    }
}

#[typetag::serde(name = "offset")]
impl ForceLaw for Offset {
    #[inline]
    fn force(&self, theta: f64, u: f64, du: f64) -> f64 {
        self.law.force(theta, u - self.offset, du)
    }
    fn force_batch(&self, theta: &[f64], u: &[f64], du: &[f64], out: &mut [f64]) {
        self.blocks(theta, u, |start, t, s| {
            let end = start + t.len();
            self.law
                .force_batch(t, s, &du[start..end], &mut out[start..end]);
        });
    }
    fn derivatives_batch(
        &self,
        theta: &[f64],
        u: &[f64],
        du: &[f64],
        dfdu: &mut [f64],
        dfddu: &mut [f64],
    ) {
        self.blocks(theta, u, |start, t, s| {
            let end = start + t.len();
            self.law.derivatives_batch(
                t,
                s,
                &du[start..end],
                &mut dfdu[start..end],
                &mut dfddu[start..end],
            );
        });
    }
    #[inline]
    fn derivatives(&self, theta: f64, u: f64, du: f64) -> (f64, f64) {
        self.law.derivatives(theta, u - self.offset, du)
    }
    fn linear_part(&self) -> LinearPart {
        let inner = self.law.linear_part();
        LinearPart {
            offset: inner.offset - inner.stiffness * self.offset,
            ..inner
        }
    }
    fn time_breakpoints(&self) -> Vec<f64> {
        self.law.time_breakpoints()
    }
    fn time_order(&self) -> Option<usize> {
        self.law.time_order()
    }
    fn band_limited(&self, samples: usize, max_order: usize) -> Option<Box<dyn ForceLaw>> {
        let law = self.law.band_limited(samples, max_order)?;
        Some(Box::new(Self::boxed(self.offset, law)))
    }
    fn kinks(&self) -> Vec<f64> {
        self.law.kinks().iter().map(|k| k + self.offset).collect()
    }
    fn state_names(&self) -> &'static [&'static str] {
        self.law.state_names()
    }

    fn memory(&self) -> Option<&dyn Hysteresis> {
        // The law's memory on the shifted coordinate: `self` forwards the steps.
        self.law.memory().map(|_| self as &dyn Hysteresis)
    }
    fn is_linear_time_invariant(&self) -> bool {
        // Exact: f = k0 (u - u0) + d0 u̇ + f0 = k0 u + d0 u̇ + (f0 - k0 u0), and the residual
        // carries every element's static offset as a load (also for LTI elements).
        self.law.is_linear_time_invariant()
    }
    fn is_linear_in_state(&self) -> bool {
        // Not in the state alone: the shift adds the force at rest -k(θ) u0.
        false
    }
    fn is_piecewise_constant(&self) -> bool {
        // The shift keeps the coefficients; the force at rest -k(θ) u0 jumps with them.
        self.law.is_piecewise_constant()
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_finite(context, "offset", self.offset)?;
        self.law.validate(context)
    }
}

/// The memory of the wrapped law on `u - u0`. Only reached through [`ForceLaw::memory`], which
/// returns it when the wrapped law has memory.
impl Hysteresis for Offset {
    fn state_len(&self) -> usize {
        self.law.memory().map_or(0, |m| m.state_len())
    }
    fn initial_state(&self, state: &mut [f64]) {
        if let Some(m) = self.law.memory() {
            m.initial_state(state);
        }
    }
    #[inline]
    fn step(&self, theta: f64, u: f64, du: f64, state: &mut [f64]) -> f64 {
        match self.law.memory() {
            Some(m) => m.step(theta, u - self.offset, du, state),
            None => self.law.force(theta, u - self.offset, du),
        }
    }
    #[inline]
    fn step_derivatives(
        &self,
        theta: f64,
        u: f64,
        du: f64,
        state: &mut [f64],
        d: &mut StepDerivatives,
    ) -> f64 {
        match self.law.memory() {
            Some(m) => m.step_derivatives(theta, u - self.offset, du, state, d),
            None => {
                (d.df_du, d.df_ddu) = self.law.derivatives(theta, u - self.offset, du);
                self.law.force(theta, u - self.offset, du)
            }
        }
    }
}
