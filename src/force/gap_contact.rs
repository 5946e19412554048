//! `gap_contact`: a one-sided contact `f = k(φ) (u - g) + c u̇` for `u > g`, else 0.

use super::profile::jump_angles;
use super::{ForceLaw, LinearPart, MeshProfile};
use crate::error::{check_finite, check_non_negative, Result};

/// One-sided (unilateral) contact with a gap:
///
/// `f = k(φ) (u - g) + c u̇` for `u > g`, `f = 0` for `u <= g`,
///
/// gap `g` (m or rad; negative: a preloaded contact, closed at rest), contact stiffness `k(φ)`
/// (constant, or a [`MeshProfile`] over `φ = z θ + φ0` for a contact whose stiffness varies with
/// the shaft angle), and contact damping `c` acting only in contact. It pushes only one way; a
/// stop on the other side is a second element with negative weights (`u = -w·q`).
///
/// As for [`Backlash`](super::Backlash), the damping acts in contact even while the bodies
/// separate (`u̇ < 0`), so the force may pull slightly before the contact opens (the usual
/// Kelvin–Voigt contact).
///
/// **Linear part.** [`ContactState::Auto`] (the default) centres the iteration on the state of
/// the contact at rest, `u = 0`: open (`k0 = d0 = 0`) for `g >= 0`, closed for a preload
/// `g < 0` (`f ≈ k̄ (u - g) + c u̇`, offset `-k̄ g`, mean stiffness `k̄`) — the linearisation at
/// `u = u̇ = 0`, as the trait's default. `Open` or `Closed` force either centre: a contact
/// that is driven closed by a static load starts better from `Closed`. Only the first iterate
/// and the paper's split depend on it.
///
/// ```
/// use hbal::force::{ForceLaw, GapContact};
/// // NLvib's unilateral spring: k = 100, gap 1.
/// let stop = GapContact::new(1.0, 100.0);
/// assert_eq!(stop.force(0.0, 0.5, 3.0), 0.0);                // open
/// assert!((stop.force(0.0, 1.25, 0.0) - 25.0).abs() < 1e-12); // 100 (1.25 - 1)
/// assert_eq!(stop.kinks(), vec![1.0]);
/// assert_eq!(stop.linear_part().stiffness, 0.0);              // open at rest
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GapContact {
    /// Gap g (finite, m or rad); negative for a preloaded contact.
    pub gap: f64,
    /// Contact stiffness (N/m or N m/rad): a number, or a profile table such as
    /// `{ shape = "cosine", mean, amplitude }`.
    #[serde(deserialize_with = "number_or_profile")]
    pub stiffness: MeshProfile,
    /// Stiffness cycles per fundamental period z (>= 1), default 1.
    #[serde(default = "one")]
    pub teeth: u32,
    /// Phase φ0 of the stiffness profile in rad, default 0.
    #[serde(default)]
    pub phase: f64,
    /// Contact damping c (>= 0, N s/m or N m s/rad), acting only in contact; default 0.
    #[serde(default)]
    pub contact_damping: f64,
    /// The state the iteration linearises about: `auto` (default), `open` or `closed`.
    #[serde(default)]
    pub linearize: ContactState,
}

/// The contact state a [`GapContact`]'s linear part describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactState {
    /// The state at rest: closed if the gap is negative (preload), open otherwise.
    #[default]
    Auto,
    /// Open: `k0 = d0 = 0`.
    Open,
    /// Closed: `f ≈ k̄ (u - g) + c u̇`.
    Closed,
}

fn one() -> u32 {
    1
}

/// A stiffness given as a plain number (a constant profile) or as a profile table.
fn number_or_profile<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> std::result::Result<MeshProfile, D::Error> {
    use serde::de::Error as _;
    let value = <serde_json::Value as serde::Deserialize>::deserialize(d)?;
    match value.as_f64() {
        Some(stiffness) => Ok(MeshProfile::Constant { stiffness }),
        None => serde_json::from_value(value).map_err(D::Error::custom),
    }
}

impl GapContact {
    /// A contact with gap `g` and constant stiffness `k`, no damping.
    pub fn new(gap: f64, stiffness: f64) -> Self {
        Self::with_profile(gap, MeshProfile::Constant { stiffness })
    }

    /// A contact with gap `g` and stiffness profile `stiffness` (one cycle per period).
    pub fn with_profile(gap: f64, stiffness: MeshProfile) -> Self {
        Self {
            gap,
            stiffness,
            teeth: 1,
            phase: 0.0,
            contact_damping: 0.0,
            linearize: ContactState::Auto,
        }
    }

    /// Sets the contact damping c.
    pub fn with_contact_damping(mut self, c: f64) -> Self {
        self.contact_damping = c;
        self
    }

    /// Sets the number of stiffness cycles per period z.
    pub fn with_teeth(mut self, teeth: u32) -> Self {
        self.teeth = teeth;
        self
    }

    /// Sets the state the iteration linearises about.
    pub fn with_linearize(mut self, state: ContactState) -> Self {
        self.linearize = state;
        self
    }

    #[inline]
    fn stiffness_at(&self, theta: f64) -> f64 {
        self.stiffness.value(self.teeth as f64 * theta + self.phase)
    }
}

#[typetag::serde(name = "gap_contact")]
impl ForceLaw for GapContact {
    #[inline]
    fn force(&self, theta: f64, u: f64, du: f64) -> f64 {
        if u > self.gap {
            self.stiffness_at(theta) * (u - self.gap) + self.contact_damping * du
        } else {
            0.0
        }
    }
    fn force_batch(&self, theta: &[f64], u: &[f64], du: &[f64], out: &mut [f64]) {
        let mut k = [0.0; 64];
        let (g, c) = (self.gap, self.contact_damping);
        for (start, t) in (0..theta.len()).step_by(64).zip(theta.chunks(64)) {
            self.stiffness
                .values_into(self.teeth as f64, self.phase, t, &mut k);
            for (j, kj) in k[..t.len()].iter().enumerate() {
                let (x, v) = (u[start + j], du[start + j]);
                out[start + j] = if x > g { kj * (x - g) + c * v } else { 0.0 };
            }
        }
    }
    fn derivatives_batch(
        &self,
        theta: &[f64],
        u: &[f64],
        _du: &[f64],
        dfdu: &mut [f64],
        dfddu: &mut [f64],
    ) {
        let mut k = [0.0; 64];
        for (start, t) in (0..theta.len()).step_by(64).zip(theta.chunks(64)) {
            self.stiffness
                .values_into(self.teeth as f64, self.phase, t, &mut k);
            for (j, kj) in k[..t.len()].iter().enumerate() {
                let closed = u[start + j] > self.gap;
                dfdu[start + j] = if closed { *kj } else { 0.0 };
                dfddu[start + j] = if closed { self.contact_damping } else { 0.0 };
            }
        }
    }
    #[inline]
    fn derivatives(&self, theta: f64, u: f64, _du: f64) -> (f64, f64) {
        if u > self.gap {
            (self.stiffness_at(theta), self.contact_damping)
        } else {
            (0.0, 0.0)
        }
    }
    fn linear_part(&self) -> LinearPart {
        let closed = match self.linearize {
            ContactState::Auto => self.gap < 0.0,
            ContactState::Open => false,
            ContactState::Closed => true,
        };
        if !closed {
            return LinearPart::default();
        }
        let k = self.stiffness.mean();
        LinearPart {
            stiffness: k,
            damping: self.contact_damping,
            offset: -k * self.gap,
        }
    }
    fn kinks(&self) -> Vec<f64> {
        vec![self.gap]
    }
    fn state_names(&self) -> &'static [&'static str] {
        &["open", "contact"]
    }
    fn time_breakpoints(&self) -> Vec<f64> {
        jump_angles(&self.stiffness.jumps(), self.teeth, self.phase)
    }
    fn time_order(&self) -> Option<usize> {
        self.stiffness.time_order(self.teeth)
    }
    fn band_limited(&self, samples: usize, max_order: usize) -> Option<Box<dyn ForceLaw>> {
        let stiffness = self
            .stiffness
            .for_samples(self.teeth, self.phase, samples, max_order)?;
        Some(Box::new(Self {
            stiffness,
            ..self.clone()
        }))
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_finite(context, "gap", self.gap)?;
        super::profile::check_teeth(context, self.teeth)?;
        check_finite(context, "phase", self.phase)?;
        check_non_negative(context, "contact_damping", self.contact_damping)?;
        self.stiffness.validate(context)
    }
}
