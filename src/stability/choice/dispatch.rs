//! Which monodromy matrix: the dense one in the model's DOFs (`2n × 2n`, `O(n³)` per
//! integration step) or the one on a reduced basis ([`reduction`](crate::stability::large::reduction): the
//! modes below a cut-off plus attachment modes, `2(r + a) × 2(r + a)` whatever n), and the
//! reduction's accuracy estimate.

use super::cache::{FloquetCache, PREDICTION_POINTS};
use super::orbit_identity::other_orbit_threshold;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solution::Solution;
use crate::stability::exponential::kept::KeptGenerators;
use crate::stability::hb_state::hb_start;
use crate::stability::large::reduction::reduced_basis;
use crate::stability::shooting::shoot::{shoot, Goal, Shot, Start};
use crate::stability::system::Coordinates;
use crate::stability::{distance, Floquet, FloquetMethod, FloquetOptions, Orbit, Reduction};

/// Largest relative distance of the exact orbit's start from the HB state for which a shooting
/// from a start predicted by earlier points is kept. Farther, it may have found another
/// periodic orbit of the same period (the period-1 orbit under a period-2 HB solution after a
/// period doubling: found by the `--all-branches` test, with multipliers of the wrong orbit),
/// and the shooting starts again from the HB state.
const PREDICTED_ORBIT_DISTANCE: f64 = 1e-2;

/// Whether the shooting starts from the start predicted by earlier points, with chord steps on
/// the previous point's monodromy matrix. It was off while the chord steps along a nearly
/// singular `Φ − I` (the backlash chain's branch switch, tests/integration/branch_switching.rs) stopped
/// 1.3e-6 from the reference multiplier; the steps ahead and the chord steps are now taken only
/// while the residual is within 100× of the converged one, and that test passes with it on.
const PREDICTED_START: bool = true;

impl FloquetOptions {
    /// The multipliers of the periodic orbit of `model` next to `solution`.
    pub fn compute(&self, model: &Model, solution: &Solution) -> Result<Floquet> {
        self.compute_with(model, solution, &mut FloquetCache::default())
    }

    /// As [`FloquetOptions::compute`], reusing what `cache` kept from earlier analyses of the
    /// same model (a sweep's points): the undamped modes of `(K0, M)` (which do not depend on
    /// the speed) and the previous point's orbit correction as the shooting's start.
    pub fn compute_with(
        &self,
        model: &Model,
        solution: &Solution,
        cache: &mut FloquetCache,
    ) -> Result<Floquet> {
        if !(self.rtol > 1e-15 && self.rtol < 1e-2) {
            return Err(Error::invalid(
                "floquet",
                "rtol",
                self.rtol,
                "in (1e-15, 1e-2)",
            ));
        }
        if self.cutoff.is_nan() || self.cutoff <= 0.0 {
            return Err(Error::invalid(
                "floquet",
                "cutoff",
                self.cutoff,
                "positive (a multiple of the highest harmonic's frequency)",
            ));
        }
        model.refuse_hysteretic("floquet")?;
        let omega = solution.basis().omega();
        model.check_load_speeds(omega, omega)?;
        // The variational equation of a law with memory is not the one of `(∂f/∂u, ∂f/∂u̇)`:
        // shooting on the time-domain model with the laws' states instead.
        if model.memory_element().is_some() {
            return crate::stability::shooting::memory_shooting::floquet(model, solution, self);
        }
        let n = model.n_dofs();
        if solution.harmonics().len() < n || solution.dof_names().len() != n {
            return Err(Error::DimensionMismatch {
                context: "floquet".into(),
                expected: format!("a solution with {n} DOFs"),
                got: format!("{} DOFs", solution.dof_names().len()),
            });
        }
        if let Some(f) =
            crate::stability::time_invariant::floquet(model, solution, &mut cache.time_invariant)?
        {
            return Ok(f);
        }
        // Every mode in the band a reduced basis keeps (a long chain at speed): the leading
        // multipliers by Arnoldi on the monodromy action instead of a dense 2n × 2n matrix.
        let band =
            self.cutoff * solution.basis().harmonics() as f64 * solution.basis().fundamental();
        if self.method == FloquetMethod::Auto
            && model.n_dofs() >= crate::stability::large::krylov_floquet::ARNOLDI_FROM
            && crate::stability::large::krylov_floquet::every_mode_below(model, band)
        {
            if let Some(f) = crate::stability::large::krylov_floquet::floquet(model, solution)? {
                return Ok(f);
            }
        }
        if self.method == FloquetMethod::Arnoldi {
            return crate::stability::large::krylov_floquet::floquet(model, solution)?.ok_or_else(|| {
                Error::invalid(
                    "floquet",
                    "method",
                    0.0,
                    "`arnoldi` needs a diagonal mass matrix, no law with memory and no rigid-body mode",
                )
            });
        }
        let (sys, reduction) = match self.method.resolve(model) {
            FloquetMethod::Reduced => {
                let (sys, info) = self.reduced_coordinates(model, solution, cache)?;
                (sys, Some(info))
            }
            _ => {
                // The monodromy matrix is dense (2n × 2n): refuse what would not fit.
                model.dense("stability (Floquet multipliers, dense method)")?;
                (Coordinates::full(model), None)
            }
        };
        let omega = solution.basis().omega();
        let mut floquet = match self.orbit {
            Orbit::Exact => self.exact_orbit(&sys, solution, cache, omega)?,
            Orbit::Harmonic => self.harmonic_orbit(&sys, solution, cache, omega)?,
        };
        if floquet.other_orbit.is_some() && floquet.orbit == Orbit::Exact {
            floquet = self.own_multipliers(&sys, solution, cache, floquet)?;
        }
        if let Some(mut info) = reduction {
            if info.dofs >= n {
                info.estimate = Some(0.0);
            }
            floquet.reduction = Some(info);
            if self.estimate {
                self.add_estimate(model, solution, &mut floquet, cache)?;
            }
        }
        Ok(floquet)
    }

    /// The multipliers of the exact orbit next to `solution` in the coordinates `sys`, by
    /// shooting: from the previous points' corrections (extrapolated along the last three) if
    /// that converges near, from the HB state otherwise.
    pub(crate) fn exact_orbit(
        &self,
        sys: &Coordinates,
        solution: &Solution,
        cache: &mut FloquetCache,
        omega: f64,
    ) -> Result<Floquet> {
        let n = sys.model.n_dofs();
        // Start from the previous points' corrections (extrapolated along the last three)
        // if it is near; from the HB state if that fails to converge. The chord steps start
        // with the previous point's monodromy matrix.
        let mut shot = None;
        let jacobian = cache.jacobian.as_ref();
        let predicted = PREDICTED_START
            .then(|| cache.predicted_correction(omega, 2 * n))
            .flatten();
        if let Some(d) = predicted {
            let s = shoot(
                sys,
                solution,
                self,
                Start::Corrected(&d),
                Goal::Exact,
                jacobian,
                &mut cache.generators,
            )?;
            if s.floquet.polished
                && s.floquet.orbit_correction <= PREDICTED_ORBIT_DISTANCE
                && s.floquet.orbit_distance <= other_orbit_threshold(solution)
            {
                shot = Some(s);
            }
        }
        // From the HB state with Newton steps (no kept Jacobian): the orbit the HB solution
        // stands for, whatever the earlier points were.
        let shot = match shot {
            Some(s) => s,
            None => shoot(
                sys,
                solution,
                self,
                Start::Hb,
                Goal::Exact,
                None,
                &mut cache.generators,
            )?,
        };
        let Shot {
            mut floquet, kappa, ..
        } = shot;
        // Possibly another orbit: the caller decides ([`FloquetOptions::own_multipliers`]).
        if floquet.orbit_distance > other_orbit_threshold(solution) {
            floquet.other_orbit = Some(floquet.orbit_distance);
        }
        cache.kappa = kappa.or(cache.kappa);
        cache.jacobian = Some(shot.jacobian);
        let correction = floquet.polished.then(|| {
            let x_hb = hb_start(solution);
            let start = shot.ahead.as_ref().unwrap_or(&floquet.orbit_start);
            let d = start.iter().zip(x_hb).map(|(a, b)| a - b);
            (omega, d.collect())
        });
        match correction {
            Some(c) => {
                if cache.corrections.len() == PREDICTION_POINTS {
                    cache.corrections.remove(0);
                }
                cache.corrections.push(c);
            }
            None => cache.corrections.clear(),
        }
        Ok(floquet)
    }

    /// The coordinates of the reduced basis with the cut-off `cutoff · H Ω/ν` (the modes
    /// computed up to twice that if the estimate is asked for, so that its basis finds them).
    fn reduced_coordinates<'m>(
        &self,
        model: &'m Model,
        solution: &Solution,
        cache: &mut FloquetCache,
    ) -> Result<(Coordinates<'m>, Reduction)> {
        let top = solution.basis().harmonics() as f64 * solution.basis().fundamental();
        let cutoff = self.cutoff * top;
        let reach = 2.0 * cutoff;
        let basis = reduced_basis(model, cutoff, reach, &mut cache.modes)?;
        let info = Reduction {
            dofs: basis.v.ncols(),
            modes: basis.modes,
            attachment: basis.attachment,
            cutoff,
            estimate: None,
            comparison_dofs: None,
            krylov: None,
        };
        Ok((
            Coordinates::reduced_with(model, basis.v, &basis.projected),
            info,
        ))
    }

    /// Adds the reduction's estimate to `floquet` (an analysis of `solution` on the reduced
    /// basis with the options' cut-off): the [`distance`] of its leading multipliers to those on
    /// the basis with twice the cut-off (doubled again, up to 2⁸ times, while that adds no
    /// vector), whose shooting starts from `floquet`'s exact orbit and stops once its
    /// multipliers are known to 1 % of that distance ([`Goal::Compare`], with the sensitivity
    /// of the last analysis kept in `cache`). Nothing for a dense analysis.
    pub(crate) fn add_estimate(
        &self,
        model: &Model,
        solution: &Solution,
        floquet: &mut Floquet,
        cache: &mut FloquetCache,
    ) -> Result<()> {
        let Some(info) = floquet.reduction.as_mut() else {
            return Ok(());
        };
        // (shooting on the wider basis would glide onto the other orbit again)
        if info.estimate.is_some() || floquet.other_orbit.is_some() {
            return Ok(());
        }
        let mut wider = 2.0 * info.cutoff;
        let mut larger = reduced_basis(model, wider, wider, &mut cache.modes)?;
        for _ in 0..7 {
            if larger.v.ncols() > info.dofs {
                break;
            }
            wider *= 2.0;
            larger = reduced_basis(model, wider, wider, &mut cache.modes)?;
        }
        info.comparison_dofs = Some(larger.v.ncols());
        // The exact orbits on both bases, also for the HB orbit's multipliers: the HB orbit's
        // pieces do not depend on the basis, so its multipliers on both would hide what the
        // basis does to the orbit (their difference to the exact orbit's on this basis is
        // `orbit_difference`).
        let exact = FloquetOptions {
            orbit: Orbit::Exact,
            ..*self
        };
        let goal = match cache.kappa {
            Some(kappa) if floquet.orbit == Orbit::Exact => Goal::Compare {
                reference: &floquet.multipliers,
                kappa,
            },
            _ => Goal::Exact,
        };
        let sys = Coordinates::reduced(model, larger.v);
        let start = Start::State(&floquet.orbit_start);
        let reference = shoot(
            &sys,
            solution,
            &exact,
            start,
            goal,
            None,
            &mut KeptGenerators::default(),
        )?
        .floquet;
        info.estimate = Some(distance(&floquet.multipliers, &reference.multipliers));
        floquet.steps += reference.steps;
        Ok(())
    }
}
