//! `jenkins`: elastic dry friction with stick and slip (a spring in series with a Coulomb
//! slider), a law with memory.

use super::memory::{Hysteresis, StepDerivatives};
use super::{ForceLaw, LinearPart};
use crate::error::{check_non_negative, Result};

/// A Jenkins element: a spring `k` in series with a Coulomb slider of limit `F_s`, plus
/// optional viscous damping `c` in parallel:
///
/// `f = k (u - z) + c u̇`, `|k (u - z)| <= F_s`,
///
/// where the slider position `z` (the state) moves only while the spring force sits on the
/// limit (slip); below it the element sticks and acts as the spring `k`. Between samples the
/// state follows the return mapping (the play operator of width `F_s / k`):
///
/// - trial `t = k (u_j - z_{j-1})`;
/// - stick `|t| <= F_s`: `z_j = z_{j-1}`, `f_j = t`;
/// - slip `|t| > F_s`: `f_j = F_s sign t`, `z_j = u_j - f_j / k`.
///
/// The slider starts at `z = 0` (the virgin state). On a periodic `u` the loop closes after at
/// most two periods; if the element sticks all the time its state stays where it started (the
/// force is then `k u`, as in NLvib's AFT, which also marches from `z = 0`).
///
/// **Memoryless view.** [`ForceLaw::force`] is the first step from the virgin state,
/// `clamp(k u, ±F_s) + c u̇`; the AFT and the time-domain reference use the memory
/// ([`ForceLaw::memory`]). **Linear part.** `k0 = k`, `d0 = c`: the element stuck.
///
/// ```
/// use hbal::force::{ForceLaw, Jenkins};
/// let j = Jenkins::new(20.0, 1.0);
/// let m = j.memory().unwrap();
/// let mut z = [0.0];
/// m.initial_state(&mut z);
/// assert_eq!(m.step(0.0, 0.02, 0.0, &mut z), 0.4);  // stick: k u
/// assert_eq!(m.step(0.0, 0.10, 0.0, &mut z), 1.0);  // slip at the limit
/// assert!((z[0] - 0.05).abs() < 1e-15);             // slider at u - F_s / k
/// assert!((m.step(0.0, 0.08, 0.0, &mut z) - 0.6).abs() < 1e-12); // stick again, unloading
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Jenkins {
    /// Stiffness k of the spring (>= 0, N/m or N m/rad).
    pub stiffness: f64,
    /// Friction limit F_s of the slider (>= 0, N or N m).
    pub limit: f64,
    /// Viscous damping c in parallel (>= 0, N s/m or N m s/rad); default 0.
    #[serde(default)]
    pub damping: f64,
}

impl Jenkins {
    /// A Jenkins element with stiffness `k` and friction limit `F_s`, no damping.
    pub fn new(stiffness: f64, limit: f64) -> Self {
        Self {
            stiffness,
            limit,
            damping: 0.0,
        }
    }

    /// Sets the parallel viscous damping c.
    pub fn with_damping(mut self, c: f64) -> Self {
        self.damping = c;
        self
    }

    /// The return mapping: `(spring force, sticks)`, and the slider moved on slip.
    #[inline]
    fn map(&self, u: f64, z: &mut f64) -> (f64, bool) {
        let trial = self.stiffness * (u - *z);
        if trial.abs() <= self.limit {
            (trial, true)
        } else {
            let f = self.limit.copysign(trial);
            *z = u - f / self.stiffness;
            (f, false)
        }
    }
}

impl Hysteresis for Jenkins {
    fn state_len(&self) -> usize {
        1
    }
    fn initial_state(&self, state: &mut [f64]) {
        state[0] = 0.0;
    }
    #[inline]
    fn step(&self, _theta: f64, u: f64, du: f64, state: &mut [f64]) -> f64 {
        self.map(u, &mut state[0]).0 + self.damping * du
    }
    #[inline]
    fn step_derivatives(
        &self,
        _theta: f64,
        u: f64,
        du: f64,
        state: &mut [f64],
        d: &mut StepDerivatives,
    ) -> f64 {
        let (f, stick) = self.map(u, &mut state[0]);
        d.df_ddu = self.damping;
        if stick {
            d.df_du = self.stiffness;
            d.df_ds[0] = -self.stiffness;
            d.ds_du[0] = 0.0;
            d.ds_ds[0][0] = 1.0;
        } else {
            d.df_du = 0.0;
            d.df_ds[0] = 0.0;
            d.ds_du[0] = 1.0;
            d.ds_ds[0][0] = 0.0;
        }
        d.ds_ddu[0] = 0.0;
        f + self.damping * du
    }
}

#[typetag::serde(name = "jenkins")]
impl ForceLaw for Jenkins {
    #[inline]
    fn force(&self, _theta: f64, u: f64, du: f64) -> f64 {
        self.map(u, &mut 0.0).0 + self.damping * du
    }
    #[inline]
    fn derivatives(&self, _theta: f64, u: f64, _du: f64) -> (f64, f64) {
        let stick = self.map(u, &mut 0.0).1;
        (if stick { self.stiffness } else { 0.0 }, self.damping)
    }
    fn linear_part(&self) -> LinearPart {
        LinearPart {
            stiffness: self.stiffness,
            damping: self.damping,
            offset: 0.0,
        }
    }
    fn memory(&self) -> Option<&dyn Hysteresis> {
        Some(self)
    }
    fn validate(&self, context: &str) -> Result<()> {
        check_non_negative(context, "stiffness", self.stiffness)?;
        check_non_negative(context, "limit", self.limit)?;
        check_non_negative(context, "damping", self.damping)
    }
}
