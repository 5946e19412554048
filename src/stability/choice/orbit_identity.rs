//! Whether the multipliers belong to the orbit reported.
//!
//! Shooting polishes the HB state at `t = 0` onto the exact periodic orbit next to it. Where
//! that orbit is strongly unstable it may not find it: on the middle branch of an S-shaped
//! run-up with contact loss the saddle's real multiplier is of order 10⁸ per period, single
//! shooting cannot resolve its unstable direction in double precision, and Newton (or a chord
//! step with the previous point's monodromy matrix) glides onto a stable orbit of the same
//! speed, whose multipliers then label the unstable branch stable. The orbit found is told
//! apart from the one reported by how far its start lies from the HB state at `t = 0`, in the
//! HB orbit's own dynamic terms ([`orbit_distance`](crate::stability::orbit_distance)): the HB solution's error there is a small
//! fraction of its vibration, the distance to another orbit of the same speed a large one.
//!
//! Measured on the single-stage drivetrain of `tests/integration/s_curve.rs`-like run-ups
//! (H = 128, contact loss up to 73 %): 1e-5 to 1e-3 where the polish stays (transmission error
//! within 0.2 %), 1.3e-2 to 2.5 where it left for another orbit (transmission error 21.8 µm
//! peak to peak polished to the upper branch's 26.9 µm, or 48.9 µm to the lower branch's
//! 5.3 µm); [`OTHER_ORBIT_DISTANCE`] lies between.

use super::cache::FloquetCache;
use crate::error::Result;
use crate::solution::Solution;
use crate::stability::shooting::shoot::{shoot, Goal, Start};
use crate::stability::system::Coordinates;
use crate::stability::OTHER_ORBIT_DISTANCE;
use crate::stability::{Floquet, FloquetOptions, Orbit};

/// How many times its truncation estimate the HB solution may lie from the exact orbit it
/// stands for ([`other_orbit_threshold`]).
const TRUNCATION_FACTOR: f64 = 4.0;

/// The [`orbit_distance`](crate::stability::orbit_distance) beyond which a shooting's orbit is taken for another orbit than the
/// HB solution's: [`OTHER_ORBIT_DISTANCE`], or [`TRUNCATION_FACTOR`] times the solution's
/// [truncation estimate](Solution::truncation_estimate) where that is larger. An HB solution
/// whose top harmonics are not small may lie that far from its own exact orbit, and the
/// linearisation about it is then no better: a Duffing oscillator at H = 1 (truncation
/// estimate 1) lies 8e-3 to 3e-2 from the exact middle-branch orbits, whose multipliers
/// (unstable) are right where the HB orbit's own (stable) are not. The S-shaped run-ups at
/// H = 128 have estimates of 2e-5 to 2e-3 and other orbits from 8e-3 on.
pub(crate) fn other_orbit_threshold(solution: &Solution) -> f64 {
    let t = solution.truncation_estimate();
    if t.is_finite() {
        OTHER_ORBIT_DISTANCE.max(TRUNCATION_FACTOR * t)
    } else {
        OTHER_ORBIT_DISTANCE
    }
}

impl FloquetOptions {
    /// Decides whose multipliers `found` (the exact orbit's, more than
    /// [`OTHER_ORBIT_DISTANCE`] from the HB orbit, [`Floquet::other_orbit`] set) should be:
    /// the HB orbit's own multipliers are compared ([`FloquetOptions::hb_orbit`]). The same
    /// kind (the same stability and number of real multipliers above +1): the HB solution is
    /// merely inaccurate (an under-resolved orbit, the two-shaft model at 60 rpm), `found`
    /// stands without the mark. Another kind: the HB orbit's own, marked.
    pub(crate) fn own_multipliers(
        &self,
        sys: &Coordinates,
        solution: &Solution,
        cache: &mut FloquetCache,
        mut found: Floquet,
    ) -> Result<Floquet> {
        // (a failure along the HB orbit leaves the exact orbit's multipliers standing)
        let Ok(mut own) = self.hb_orbit(sys, solution, cache) else {
            found.other_orbit = None;
            return Ok(found);
        };
        if !same_kind(&own, &found) {
            own.other_orbit = found.other_orbit;
            own.steps += found.steps;
            forget_orbit(cache);
            return Ok(own);
        }
        found.other_orbit = None;
        Ok(found)
    }

    /// The multipliers of the HB orbit itself, for every law: the exponential flow's pieces
    /// where every law is affine between its kinks ([`harmonic_orbit`](crate::stability::harmonic_orbit)),
    /// the Runge–Kutta flow of the variational equation along it otherwise
    /// ([`guide`](crate::stability::integrated::guide)).
    pub(crate) fn hb_orbit(
        &self,
        sys: &Coordinates,
        solution: &Solution,
        cache: &mut FloquetCache,
    ) -> Result<Floquet> {
        let harmonic = FloquetOptions {
            orbit: Orbit::Harmonic,
            ..*self
        };
        let shot = shoot(
            sys,
            solution,
            &harmonic,
            Start::Hb,
            Goal::Own,
            None,
            &mut cache.generators,
        )?;
        Ok(shot.floquet)
    }
}

/// Another orbit's monodromy matrix and corrections would lead the next points' shootings to
/// it as well: dropped.
pub(crate) fn forget_orbit(cache: &mut FloquetCache) {
    cache.jacobian = None;
    cache.corrections.clear();
}

/// The same stability and the same number of real multipliers above +1, and, where both are
/// unstable, leading moduli within a factor 2 of each other (on the frozen-stage car's middle
/// branch with a cosine mesh stiffness a shooting found an orbit with 4.1 where the HB orbit's
/// own leading multiplier is 1.1e11: another saddle).
pub(crate) fn same_kind(a: &Floquet, b: &Floquet) -> bool {
    let unstable = !a.is_stable() && !b.is_stable();
    a.is_stable() == b.is_stable()
        && a.real_unstable() == b.real_unstable()
        && !(unstable && (a.max_abs().ln() - b.max_abs().ln()).abs() > std::f64::consts::LN_2)
}
