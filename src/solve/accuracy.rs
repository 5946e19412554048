//! The accuracy of a harmonic-balance solution, and the automatic choice of H.
//!
//! **Error estimate.** The error of the harmonics `0..=H` of a solution `Q_H` is estimated by
//! its distance to the solution `Q_2H` on the basis with twice the harmonics and samples,
//! found by Newton from `Q_H` (padded with zeros; one to three iterations):
//! `d = ‖Q_H - Q_2H‖ / ‖Q_2H‖` in the Parseval norm of [`relative_error`], over the orders
//! `0..=2H` (the error of the periodic solution, including the harmonics it lacks) and over
//! `0..=H` (the error of its harmonics). If the error at least halves when H doubles,
//! `e(2H) <= e(H)/2`, then `e(H)/2 <= d <= 3 e(H)/2`: the estimate is within a factor 2 of the
//! true error, where
//! a measure of the top harmonics' size (the former truncation estimate) was up to 600 times
//! too pessimistic (a backlash contact with kink-aware quadrature) or 30 times too optimistic
//! (a stiffness jump sampled off its position). Where a law jumps in time and modes it
//! excites lie above 2H, the reference goes on to 4H or 8H ([`ringing`](super::ringing)).
//!
//! **Automatic H.** [`solve_auto`] solves at `H = H0, 2 H0, 4 H0, ...` (each level
//! warm-started from the last, and each level's 2H refinement is the next level), and returns
//! the first solution whose estimate is below the tolerance, or, at the cap, the last one with
//! a message. The estimate is that of every DOF and element coordinate by default, or the
//! whole solution's, or that of its harmonics `0..=H` alone ([`Control`]).

use crate::compare::quantities::{quantity_errors, worst};
use crate::compare::{relative_error, QuantityError};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solution::Solution;
use crate::solve::coarse::coarse_harmonics;
use crate::solve::ringing::{reference, rings_beyond};
use crate::solve::{Method, Newton};
use crate::{Formulation, HarmonicBasis};
use std::time::Instant;

/// The estimated error of a solution.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ErrorEstimate {
    /// Relative error of the periodic solution (Parseval norm, the RMS over a period), its
    /// harmonics `0..=H` and the ones it lacks, estimated against the solution with
    /// `reference_harmonics` harmonics; at least 1e-15. What automatic harmonics control.
    pub relative: f64,
    /// The same for its harmonics `0..=H` alone.
    #[serde(default)]
    pub kept_harmonics: f64,
    /// The H of the finer solution it was estimated against: 2H, or 4H or 8H where modes a
    /// law that jumps in time makes ring lie above 2H (`solve::ringing`).
    pub reference_harmonics: usize,
    /// `relative` counts only the harmonics up to `reference_harmonics`, short of where the
    /// solution is known to have content (the exact piecewise solution beyond its work
    /// budget; harmonic balance where a law jumps in time and the highest natural frequency
    /// lies above `reference_harmonics`, where the jumps ring): the true error may be larger,
    /// and automatic harmonics do not stop on it (unless they control the harmonics 0..H).
    #[serde(default)]
    pub lower_bound: bool,
    /// The worst DOF or element coordinate, each by its dynamic part relative to its own
    /// range ([`crate::compare::quantities`]), against the same finer solution: what
    /// [`Control::Quantities`] controls. `None` where not estimated.
    #[serde(default)]
    pub worst_quantity: Option<QuantityError>,
    /// The worst element force the same way (a force that jumps where a contact with damping
    /// closes is only as good as the crossing's position).
    #[serde(default)]
    pub worst_force: Option<QuantityError>,
    /// The AFT's quadrature error at the solution where a law's contact crossings take the
    /// corrected trapezoid rule instead of exact integration (a cosine or Fourier mesh
    /// stiffness under backlash, a user's law; [`crate::solve::quadrature_error`]); `None`
    /// where every crossing is integrated exactly or none is crossed.
    #[serde(default)]
    pub quadrature: Option<crate::solve::QuadratureError>,
}

/// The basis with `harmonics` harmonics at the Ω and ν of `basis`, with as many samples per
/// harmonic as it has (at least the default).
pub(super) fn scaled(basis: &HarmonicBasis, harmonics: usize) -> Result<HarmonicBasis> {
    let b = HarmonicBasis::new(basis.omega(), harmonics)?.with_tail_correction_of(basis);
    let per = basis.samples() as f64 / basis.harmonics().max(1) as f64;
    let n = ((per * harmonics as f64).ceil() as usize).max(b.samples());
    b.with_samples(n)?.with_subharmonic(basis.subharmonic())
}

/// Real unknowns above which the refinement tries Anderson before Newton.
const DENSE_REFINE: usize = 600;

/// The refinement of `solution` on the basis with twice its harmonics (Newton from it, to a
/// residual of 1e-12), or an error if Newton does not converge there.
pub(crate) fn refine(
    model: &Model,
    solution: &Solution,
    formulation: Formulation,
) -> Result<Solution> {
    refine_by(model, solution, formulation, 2)
}

/// The same on the basis with `factor` times the harmonics of `solution`.
pub(super) fn refine_by(
    model: &Model,
    solution: &Solution,
    formulation: Formulation,
    factor: usize,
) -> Result<Solution> {
    let basis = solution.basis();
    let n = model.n_dofs();
    let fine = scaled(basis, factor * basis.harmonics().max(1))?;
    let hb = HarmonicBalance::with_formulation(model, fine, formulation)?;
    let mut ws = hb.workspace();
    let start = crate::harmonic::embed(solution.harmonics(), n, 1, fine.harmonics());
    // From a start this close, Anderson's FFT-cost iterations on the two-level map beat a
    // dense Newton step once the Jacobian is large (two-shaft at H = 512: 0.4 ms against
    // 60 ms); Newton is the fallback.
    let mut sol = None;
    let coarse = coarse_harmonics(model, &fine);
    if coarse.is_some() || hb.len() * 2 > DENSE_REFINE {
        let mut anderson = crate::solve::Anderson::new()
            .with_tolerance(1e-12)?
            .with_max_iterations(500);
        anderson.coarse_harmonics = coarse;
        let a = anderson.solve_from(&hb, &start, &mut ws)?;
        sol = a.is_converged().then_some(a);
    }
    let sol = match sol {
        Some(s) => s,
        None if hb.len() * 2 <= crate::solve::MAX_DENSE_UNKNOWNS => Newton::new()
            .with_tolerance(1e-12)?
            .solve_from(&hb, &start, &mut ws)?,
        None => {
            return Err(Error::Solver {
                reason: format!(
                    "error estimate: Anderson did not converge with {} harmonics and the problem is too large for Newton's dense Jacobian",
                    fine.harmonics()
                ),
            })
        }
    };
    if sol.is_converged() {
        Ok(sol)
    } else {
        Err(Error::Solver {
            reason: format!(
                "error estimate: no converged solution with {} harmonics next to this one ({})",
                fine.harmonics(),
                sol.termination
            ),
        })
    }
}

/// The solution with twice the harmonics and samples of `solution` (four or eight times
/// where modes that a jump in time excites ring above 2H), found from it: the reference
/// [`estimate_error`] measures against (for comparing other quantities of the two,
/// such as [`crate::compare::quantity_errors`] of a chosen one).
pub fn refined_solution(model: &Model, solution: &Solution) -> Result<Solution> {
    reference(model, solution, Formulation::Auto)
}

/// The estimated error of the harmonics `0..=H` of `solution` (module documentation).
///
/// ```
/// use hbal::catalog::Duffing;
/// use hbal::solve::estimate_error;
/// use hbal::{HarmonicBalance, HarmonicBasis, Newton};
/// let model = Duffing::default().model().unwrap();
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.0, 3).unwrap()).unwrap();
/// let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
/// let e = estimate_error(&model, &sol).unwrap();
/// assert_eq!(e.reference_harmonics, 6);
/// assert!(e.relative > 1e-6 && e.relative < 1e-1);
/// ```
pub fn estimate_error(model: &Model, solution: &Solution) -> Result<ErrorEstimate> {
    if solution.basis().harmonics() == 0 {
        return Err(Error::Solver {
            reason: "a static analysis (H = 0) averages the time variation out: no error estimate against a dynamic solution".into(),
        });
    }
    let fine = reference(model, solution, Formulation::Auto)?;
    Ok(compare(model, solution, &fine))
}

/// The estimate of `coarse` against `fine`: relative distances over `0..=2H` and `0..=H`,
/// and per quantity, floored at 1e-15 (two solutions that agree to rounding do not make an
/// error of zero).
pub(super) fn compare(model: &Model, coarse: &Solution, fine: &Solution) -> ErrorEstimate {
    let n = model.n_dofs();
    let (h, h2) = (coarse.basis().harmonics(), fine.basis().harmonics());
    let errors = quantity_errors(
        model,
        fine.basis(),
        coarse.harmonics(),
        fine.harmonics(),
        fine.basis().samples(),
    )
    .unwrap_or_default();
    let floored = |e: Option<QuantityError>| {
        e.map(|e| QuantityError {
            error: e.error.max(FLOOR),
            ..e
        })
    };
    ErrorEstimate {
        lower_bound: rings_beyond(model, fine.basis()),
        worst_quantity: floored(worst(&errors, |q| q.is_motion())),
        worst_force: floored(worst(&errors, |q| !q.is_motion())),
        relative: relative_error(coarse.harmonics(), fine.harmonics(), n, h2).max(FLOOR),
        kept_harmonics: relative_error(coarse.harmonics(), fine.harmonics(), n, h).max(FLOOR),
        reference_harmonics: h2,
        quadrature: crate::solve::quadrature_error(model, coarse).ok().flatten(),
    }
}

/// The smallest estimate reported: rounding.
pub const FLOOR: f64 = 1e-15;

/// Which error automatic harmonics bring below the tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Control {
    /// The periodic solution's, including the harmonics above H it lacks
    /// ([`ErrorEstimate::relative`]): the time signal, its extremes and max |q|, relative to
    /// the whole solution (where the static wind-up of the shafts may dominate).
    Solution,
    /// Every DOF and element coordinate on its own, by its dynamic part relative to its own
    /// range ([`ErrorEstimate::worst_quantity`]): the transmission error of a gear stage is
    /// controlled even where the static wind-up of the shafts dominates the whole solution.
    /// The default: what the engineer reads.
    #[default]
    Quantities,
    /// Its harmonics `0..=H` alone ([`ErrorEstimate::kept_harmonics`]): order amplitudes and
    /// phases, the order cuts of a run-up. A jumping mesh stiffness leaves the harmonics above
    /// H with content that decays like H^-2.5, so the whole solution needs many more
    /// harmonics than its orders (the two-shaft model at 6000 rpm: H = 32 against 512 for
    /// 1e-6).
    Harmonics,
}

impl Control {
    /// `solution` or `harmonics`, whichever this control names (`solution` for the
    /// quantities: they include what the solution lacks above H).
    pub fn pick<T>(self, solution: T, harmonics: T) -> T {
        match self {
            Control::Solution | Control::Quantities => solution,
            Control::Harmonics => harmonics,
        }
    }

    /// The controlled part of `estimate` (the whole solution's where the quantities were
    /// not estimated).
    pub fn of(self, estimate: &ErrorEstimate) -> f64 {
        match (self, estimate.worst_quantity) {
            (Control::Quantities, Some(q)) => q.error,
            _ => self.pick(estimate.relative, estimate.kept_harmonics),
        }
    }

    /// What is controlled, in words.
    pub fn what(self) -> &'static str {
        match self {
            Control::Solution => "the periodic solution",
            Control::Quantities => "every DOF and element coordinate",
            Control::Harmonics => "the harmonics 0..H",
        }
    }
}

/// Settings of the automatic choice of H.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoHarmonics {
    /// The relative error to reach (> 0).
    pub tolerance: f64,
    /// The largest H tried (the refinement of the last level uses twice as many).
    pub max_harmonics: usize,
    /// The formulation of every level. Default [`Formulation::Auto`].
    pub formulation: Formulation,
    /// Which error the tolerance applies to. Default [`Control::Quantities`].
    pub control: Control,
}

impl Default for AutoHarmonics {
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_harmonics: 512,
            formulation: Formulation::Auto,
            control: Control::Solution,
        }
    }
}

/// One level of [`solve_auto`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Level {
    /// H.
    pub harmonics: usize,
    /// N.
    pub samples: usize,
    /// Its estimated error, the part [`AutoHarmonics::control`] controls.
    pub estimate: f64,
    /// Wall time of its solve and refinement, s.
    pub seconds: f64,
}

/// The result of [`solve_auto`].
#[derive(Debug, Clone)]
pub struct AutoSolution {
    /// The solution at the chosen H.
    pub solution: Solution,
    /// Its estimated error.
    pub estimate: ErrorEstimate,
    /// Every level tried.
    pub levels: Vec<Level>,
    /// `true` if the tolerance was not reached by `max_harmonics`.
    pub capped: bool,
    /// The exact piecewise solution at the chosen H where the method is
    /// [`Method::PiecewiseExact`] (its closed form in time, its multipliers), or where harmonic
    /// balance could not reach the tolerance by the cap and the exact method could
    /// (`switched_to_exact`).
    pub exact: Option<crate::solve::piecewise::ExactSolution>,
    /// `true` where harmonic balance stopped at the cap above the tolerance and the model
    /// admits the exact piecewise solution, which reached it: `solution` is that one, and
    /// `levels` holds harmonic balance's levels and then the exact method's.
    pub switched_to_exact: bool,
    /// The path that found the first level's solution where the method alone did not from
    /// the linear solution (the other solvers, the load or speed homotopy, a higher H), with
    /// what failed before; `None` where it did.
    pub found_by: Option<String>,
    /// Where a level after the first failed (its solve or its refinement at 2H): why.
    /// `solution`, `estimate` and `levels` are then those of the levels that succeeded, and
    /// `capped` is `true` (the tolerance was not reached).
    pub stopped: Option<String>,
}

/// The first level of automatic harmonics for `basis`: H doubled from the scene's count (at
/// least 1) until every load and mesh order of `model` is present, at most `auto`'s cap;
/// an error where the cap is below those orders.
pub fn auto_first_basis(
    model: &Model,
    basis: HarmonicBasis,
    auto: &AutoHarmonics,
) -> Result<HarmonicBasis> {
    // Start with every order present (a mesh order above the first H would be refused).
    let orders = model.max_order() * basis.subharmonic();
    if auto.max_harmonics < orders {
        return Err(Error::invalid(
            "harmonics",
            "max",
            auto.max_harmonics as f64,
            format!(">= {orders}, the highest load or mesh order of the model"),
        ));
    }
    let mut first = basis.harmonics().max(1);
    while first < orders {
        first *= 2;
    }
    let basis = scaled(&basis, first.min(auto.max_harmonics.max(orders)))?;
    if auto.max_harmonics < basis.harmonics().max(1) {
        return Err(Error::invalid(
            "harmonics",
            "max",
            auto.max_harmonics as f64,
            format!(">= the starting H {}", basis.harmonics()),
        ));
    }
    Ok(basis)
}

/// Solves `model` at H = H0, 2 H0, ... from `basis` (its Ω, its H as H0 and its samples per
/// harmonic) with `method` (falling back to the other solvers and a load homotopy at the
/// first level), until the estimated error of a level is at most `auto.tolerance`.
///
/// The tail correction ([`HarmonicBasis::with_tail_correction`]) is on unless `basis` turns
/// it off: where a coefficient jumps in time it reaches a tolerance at a much lower H (the
/// two-shaft model at 6000 rpm: 1e-6 at H = 32 instead of 512).
pub fn solve_auto(
    model: &Model,
    basis: HarmonicBasis,
    method: &Method,
    auto: AutoHarmonics,
) -> Result<AutoSolution> {
    let basis = basis.with_tail_correction(basis.tail_correction_setting().unwrap_or(true));
    if !(auto.tolerance.is_finite() && auto.tolerance > 0.0) {
        return Err(Error::invalid(
            "harmonics",
            "tolerance",
            auto.tolerance,
            "finite and > 0",
        ));
    }
    let basis = auto_first_basis(model, basis, &auto)?;
    if let Method::PiecewiseExact(exact) = method {
        return auto_exact(model, basis, exact, auto);
    }
    let mut level_basis = scaled(&basis, basis.harmonics().max(1))?;
    let started = Instant::now();
    let (mut current, found_by) =
        super::auto_start::first_level(model, level_basis, method, &auto)?;
    level_basis = *current.basis();
    let mut levels = Vec::new();
    // The last level that succeeded, kept where a later one fails.
    let mut last: Option<(Solution, ErrorEstimate)> = None;
    loop {
        let failed = if !current.is_converged() {
            Err(format!(
                "no converged solution with H = {} ({})",
                level_basis.harmonics(),
                current.termination
            ))
        } else {
            reference(model, &current, auto.formulation).map_err(|e| {
                format!(
                    "the refinement of H = {} failed: {e}",
                    level_basis.harmonics()
                )
            })
        };
        let fine = match (failed, last.take()) {
            (Ok(fine), _) => fine,
            (Err(reason), None) => {
                return Err(Error::Solver {
                    reason: format!("automatic harmonics: {reason}"),
                })
            }
            (Err(reason), Some((solution, estimate))) => {
                return Ok(hb_levels(solution, estimate, levels, found_by, Err(reason)))
            }
        };
        let estimate = compare(model, &current, &fine);
        levels.push(Level {
            harmonics: level_basis.harmonics(),
            samples: level_basis.samples(),
            estimate: auto.control.of(&estimate),
            seconds: started.elapsed().as_secs_f64(),
        });
        // A lower bound is no reason to stop, unless only the harmonics 0..H count.
        let bound_only = estimate.lower_bound && auto.control != Control::Harmonics;
        let reached = auto.control.of(&estimate) <= auto.tolerance && !bound_only;
        // The next level has 2H (the reference may have more, where modes ring above 2H).
        let capped = !reached && 2 * level_basis.harmonics() > auto.max_harmonics;
        if capped {
            if let Some(exact) = exact_instead(model, basis, auto, &levels) {
                return Ok(exact);
            }
        }
        if reached || capped {
            return Ok(hb_levels(current, estimate, levels, found_by, Ok(capped)));
        }
        let next = if fine.basis().harmonics() <= auto.max_harmonics {
            Ok(fine)
        } else {
            refine(model, &current, auto.formulation)
        };
        match next {
            Ok(next) => last = Some((std::mem::replace(&mut current, next), estimate)),
            Err(e) => {
                let why = Err(format!("the next level failed: {e}"));
                return Ok(hb_levels(current, estimate, levels, found_by, why));
            }
        }
        level_basis = *current.basis();
    }
}

/// The result of harmonic balance's levels ending at `solution` with `estimate`: `Ok(capped)`
/// where they ended normally, `Err(why)` where a later level failed (then capped, `stopped`).
fn hb_levels(
    solution: Solution,
    estimate: ErrorEstimate,
    levels: Vec<Level>,
    found_by: Option<String>,
    end: std::result::Result<bool, String>,
) -> AutoSolution {
    AutoSolution {
        solution,
        estimate,
        levels,
        capped: end.as_ref().map_or(true, |capped| *capped),
        exact: None,
        switched_to_exact: false,
        found_by,
        stopped: end.err(),
    }
}

/// Where harmonic balance stopped at the cap with its levels `hb_levels` above the tolerance:
/// the exact piecewise solution on the basis of the last level (the H a sweep or comparison
/// then uses), if the model admits the method and its harmonics `0..=H` reach the tolerance;
/// else `None`. Its time series and
/// extremes come from its closed form in time, so what its harmonics lack above H (a stiffness
/// jump ringing at a natural frequency far above the orders) is no error of theirs.
fn exact_instead(
    model: &Model,
    basis: HarmonicBasis,
    auto: AutoHarmonics,
    hb_levels: &[Level],
) -> Option<AutoSolution> {
    let exact = crate::solve::PiecewiseExact::default();
    crate::solve::PiecewiseExact::check(model).ok()?;
    let harmonics = AutoHarmonics {
        control: Control::Harmonics,
        ..auto
    };
    let last = hb_levels.last().map_or(basis.harmonics(), |l| l.harmonics);
    let basis = scaled(&basis, last).ok()?;
    let mut found = auto_exact(model, basis, &exact, harmonics).ok()?;
    if found.capped {
        return None;
    }
    let mut levels = hb_levels.to_vec();
    levels.append(&mut found.levels);
    found.levels = levels;
    found.switched_to_exact = true;
    Some(found)
}

/// [`solve_auto`] with the exact piecewise solution: its harmonics `0..=H` are exact, so only
/// what the periodic solution lacks above H decides; H doubles until that is within the
/// tolerance (each level is one exact solve, no refinement).
fn auto_exact(
    model: &Model,
    basis: HarmonicBasis,
    exact: &crate::solve::PiecewiseExact,
    auto: AutoHarmonics,
) -> Result<AutoSolution> {
    let started = Instant::now();
    let mut level_basis = basis;
    let mut levels = Vec::new();
    loop {
        let e = exact.solve_exact(model, &level_basis)?;
        levels.push(Level {
            harmonics: level_basis.harmonics(),
            samples: level_basis.samples(),
            estimate: auto.control.of(&e.estimate),
            seconds: started.elapsed().as_secs_f64(),
        });
        // What the solution lacks is a lower bound where the work budget cut its count
        // short: not a reason to stop (a larger H lifts 2H towards the ringing).
        let bound_only = e.estimate.lower_bound && auto.control == Control::Solution;
        let reached = auto.control.of(&e.estimate) <= auto.tolerance && !bound_only;
        let next = 2 * level_basis.harmonics().max(1);
        let capped = !reached && next > auto.max_harmonics;
        if reached || capped {
            return Ok(AutoSolution {
                solution: e.solution.clone(),
                estimate: e.estimate,
                levels,
                capped,
                exact: Some(e),
                switched_to_exact: false,
                found_by: None,
                stopped: None,
            });
        }
        level_basis = scaled(&level_basis, next)?;
    }
}
