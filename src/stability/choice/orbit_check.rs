//! The multipliers of the HB orbit itself ([`Orbit::Harmonic`]) and how a sweep keeps them
//! honest: the exact orbit's multipliers are computed too at the first analysis, at every
//! [`ORBIT_CHECK_EVERY`]-th, where the multipliers have moved by [`CHECK_MOVE`] since, and
//! wherever a multiplier lies so close to the unit circle that the measured difference could
//! change the decision (the exact orbit's are then the answer); their distance is reported
//! with every point ([`Floquet::orbit_difference`]).
//!
//! Measured on the backlash chain of `tests/data/floquet/` the HB orbit's multipliers
//! converge like H⁻³ to the references (9.8e-3, 1.3e-3, 1.7e-4, 2.1e-5 at H = 16 … 128), and
//! the measured difference is that error. On a reduced basis the difference is measured
//! against the exact orbit on the same basis (which cannot hold the contact modes' ringing
//! either): on the 1000-DOF drivetrain at H = 32 (orbit correction 2e-4 to 1e-3) the leading
//! pair agrees to 1e-10, the next to 1.1e-5 … 2.1e-5; what the basis does to the exact orbit
//! is the reduction's estimate, which for the HB orbit's multipliers compares them with the
//! exact orbit's on the wider basis (both errors together).

use super::cache::FloquetCache;
use super::orbit_identity::{forget_orbit, same_kind};
use crate::error::Result;
use crate::solution::Solution;
use crate::stability::distance;
use crate::stability::shooting::shoot::{shoot, Goal, Start};
use crate::stability::system::Coordinates;
use crate::stability::{
    Floquet, FloquetOptions, Integrator, Orbit, ORBIT_CHECK_EVERY, STABILITY_MARGIN,
};
use num_complex::Complex64;

/// How far the leading multipliers may move ([`distance`]) from those of the last measurement
/// before the HB orbit's are measured against the exact orbit's again: the difference grows
/// with the multipliers' sensitivity, which changes where they move (a branch point).
const CHECK_MOVE: f64 = 0.2;

impl FloquetOptions {
    /// The multipliers of the HB orbit itself ([`Orbit::Harmonic`]), measured against the
    /// exact orbit's at the first analysis of `cache`, at every [`ORBIT_CHECK_EVERY`]-th,
    /// where the leading multipliers have moved by more than [`CHECK_MOVE`] since the last
    /// measurement, and where one lies within ten times its measured difference of the unit
    /// circle (the exact orbit's multipliers are then the answer). Laws that are not piecewise
    /// affine: the exact orbit.
    pub(crate) fn harmonic_orbit(
        &self,
        sys: &Coordinates,
        solution: &Solution,
        cache: &mut FloquetCache,
        omega: f64,
    ) -> Result<Floquet> {
        let exact = FloquetOptions {
            orbit: Orbit::Exact,
            ..*self
        };
        if cache.exact_only || self.integrator != Integrator::Auto {
            return exact.exact_orbit(sys, solution, cache, omega);
        }
        let shot = shoot(
            sys,
            solution,
            self,
            Start::Hb,
            Goal::Exact,
            None,
            &mut cache.generators,
        )?;
        // The HB orbit's monodromy matrix starts the chord steps of the next exact shooting;
        // the corrections of earlier exact orbits would be extrapolated too far.
        cache.jacobian = Some(shot.jacobian);
        cache.corrections.clear();
        let mut floquet = shot.floquet;
        if floquet.orbit != Orbit::Harmonic {
            // Not piecewise affine: shot from the HB state onto the exact orbit; the next
            // points start where exact orbits do.
            cache.kappa = shot.kappa.or(cache.kappa);
            cache.exact_only = true;
            return Ok(floquet);
        }
        if let Some(check) = cache.orbit_check.as_mut().filter(|c| {
            c.since + 1 < ORBIT_CHECK_EVERY
                && !c.too_close(&floquet.multipliers)
                && distance(&c.harmonic(), &floquet.multipliers) <= CHECK_MOVE
        }) {
            check.since += 1;
            floquet.orbit_difference = Some(check.distance);
            return Ok(floquet);
        }
        let mut exact = exact.exact_orbit(sys, solution, cache, omega)?;
        if exact.other_orbit.is_some() && same_kind(&exact, &floquet) {
            // Far, but the same kind of orbit: the HB solution is inaccurate.
            exact.other_orbit = None;
        }
        if exact.other_orbit.is_some() {
            // The shooting found another orbit: nothing to measure against, and the HB
            // orbit's multipliers are the answer (measured again at the next point).
            cache.orbit_check = None;
            forget_orbit(cache);
            floquet.other_orbit = exact.other_orbit;
            floquet.steps += exact.steps;
            return Ok(floquet);
        }
        // Reported: the larger of this and the last measurement (the difference is not
        // smooth in Ω: it follows the HB solution's error at the kinks).
        let measured = floquet.distance(&exact);
        let difference = cache
            .orbit_check
            .as_ref()
            .map_or(measured, |c| c.measured.max(measured));
        let mut check = OrbitCheck::new(&floquet.multipliers, &exact.multipliers, difference);
        check.measured = measured;
        let too_close = check.too_close(&floquet.multipliers);
        cache.orbit_check = Some(check);
        if too_close {
            let mut exact = exact;
            exact.steps += floquet.steps;
            return Ok(exact);
        }
        floquet.orbit_difference = Some(difference);
        floquet.steps += exact.steps;
        Ok(floquet)
    }
}

/// The HB orbit's multipliers against the exact orbit's at the last point where both were
/// computed, and the analyses since.
#[derive(Debug, Clone)]
pub(crate) struct OrbitCheck {
    /// What is reported: the larger of the last two measurements of their [`distance`].
    pub(crate) distance: f64,
    /// The last measurement alone.
    pub(crate) measured: f64,
    /// The leading HB-orbit multipliers (at most 8) and each one's distance to the nearest
    /// exact one.
    leading: Vec<(Complex64, f64)>,
    pub(crate) since: usize,
}

impl OrbitCheck {
    pub(crate) fn new(harmonic: &[Complex64], exact: &[Complex64], distance: f64) -> Self {
        let leading = harmonic
            .iter()
            .take(8)
            .map(|m| {
                let d = exact
                    .iter()
                    .map(|o| (m - o).norm())
                    .fold(m.norm(), f64::min);
                (*m, d)
            })
            .collect();
        Self {
            distance,
            measured: distance,
            leading,
            since: 0,
        }
    }

    /// The leading HB-orbit multipliers of the measurement.
    fn harmonic(&self) -> Vec<Complex64> {
        self.leading.iter().map(|c| c.0).collect()
    }

    /// `true` if a leading multiplier of `multipliers` lies within ten times the measured
    /// difference of its nearest checked multiplier (plus [`STABILITY_MARGIN`]) of the unit
    /// circle: the stability decision, or a bifurcation's place, is then the exact orbit's to
    /// make.
    pub(crate) fn too_close(&self, multipliers: &[Complex64]) -> bool {
        multipliers.iter().take(8).any(|m| {
            let d = self
                .leading
                .iter()
                .min_by(|a, b| (a.0 - m).norm().total_cmp(&(b.0 - m).norm()))
                .map_or(self.distance, |c| c.1);
            (m.norm() - 1.0).abs() <= 10.0 * d + STABILITY_MARGIN
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A multiplier is too close to call where its distance from the unit circle is within
    /// ten times the measured difference of its nearest measured multiplier: the accurate
    /// leading one (1e-10) may come within 1e-8 of the circle, the inaccurate second (1e-4)
    /// not within 1e-3.
    #[test]
    fn too_close_follows_each_multipliers_own_difference() {
        let c = |re: f64, im: f64| Complex64::new(re, im);
        let harmonic = [c(0.99, 0.1), c(0.99, -0.1), c(0.99, 0.0)];
        let exact = [
            c(0.99, 0.1 + 1e-10),
            c(0.99, -0.1 - 1e-10),
            c(0.99 + 1e-4, 0.0),
        ];
        let check = OrbitCheck::new(&harmonic, &exact, 1e-4);
        assert!((check.leading[0].1 - 1e-10).abs() < 1e-15);
        assert!((check.leading[2].1 - 1e-4).abs() < 1e-12);
        // Later: the pair at 1 - 1e-5 (far beyond 10 × 1e-10 + 1e-6), the real one at 0.98.
        let on = |modulus: f64| modulus / 0.99f64.hypot(0.1);
        let r = on(1.0 - 1e-5);
        let later = [c(0.99 * r, 0.1 * r), c(0.99 * r, -0.1 * r), c(0.98, 0.0)];
        assert!(!check.too_close(&later));
        // The real one at 0.9995: within 10 × 1e-4 of the circle.
        let later = [c(0.99, 0.1), c(0.99, -0.1), c(0.9995, 0.0)];
        assert!(check.too_close(&later));
        // The pair within the stability margin of the circle.
        let r = on(1.0 - 5e-7);
        let later = [c(0.99 * r, 0.1 * r), c(0.99 * r, -0.1 * r), c(0.98, 0.0)];
        assert!(check.too_close(&later));
    }
}
