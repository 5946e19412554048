//! Floquet multipliers of a model with a law that has memory (a Jenkins slider, a clutch
//! damper's friction hysteresis), by shooting on the time-domain model with the laws' states.
//!
//! The variational equation of `(∂f/∂u, ∂f/∂u̇)` misses what such a law remembers, so the state
//! is extended by the laws' internal states `s` (the slider positions): `x = (q, q̇, s)`. The
//! period map `P(x) = x(νT)` is the time-domain reference's own integration over one orbit
//! period (DOP853 to `rtol ≤ 1e-10`, restarted at every time jump, the states committed after
//! every step; [`crate::timesim`]). Its periodic point is found by Newton shooting from the HB
//! orbit, `x ← x - (J - I)⁻¹ (P(x) - x)`, the Jacobian `J = ∂P/∂x` by forward differences;
//! the multipliers are the eigenvalues of `J` by central differences at the periodic point,
//! steps `ε_i = 1e-5 s_i` on the scales `s_i` of the orbit (`max |q_i|`, `max |q̇_i|`, the range
//! of the element coordinate for its law's state).
//!
//! The start: `(q, q̇)` of the HB orbit at `t = 0` and the laws' states at `θ = 0` from their
//! march along the HB orbit (from the virgin state, pass after pass until the loop closes, as
//! the AFT does). A law that sticks over the whole period keeps a multiplier 1 (a family of
//! orbits offset in the slider position); one that slips forgets its state (multiplier 0).
//! The cost is `2(2n + s)` period integrations for the multipliers plus `2n + s + 1` per
//! Newton step: small models only ([`MAX_DOFS`]), and grounded ones ([`available`]).

use crate::error::{Error, Result};
use crate::model::Model;
use crate::solution::Solution;
use crate::stability::neutral::rigid_body_modes;
use crate::stability::system::Coordinates;
use crate::stability::{orbit_distance, Floquet, FloquetOptions, Orbit};
use crate::timesim::PeriodMap;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Largest model whose multipliers are computed by finite differences.
pub const MAX_DOFS: usize = 64;

/// Newton steps of the shooting.
const MAX_NEWTON: usize = 10;

/// The shooting has converged once `max_i |P(x)_i - x_i| / s_i` is below this (the period
/// map's own noise, the integration to 1e-10 with the laws' states committed step by step, is
/// about 1e-8 of the scales), or once it stops falling below [`NOISE`].
const CONVERGED: f64 = 1e-8;

/// Where the shooting may stop falling.
const NOISE: f64 = 1e-6;

/// Relative finite-difference step: the map's noise of about 1e-8 makes 1e-3 of a column; the
/// multipliers of the clutch damper moved by 3e-4 between steps of 1e-6 and 1e-4.
const STEP: f64 = 1e-5;

/// Samples per period of the march of the laws' states along the HB orbit (at least).
const MARCH_SAMPLES: usize = 512;

/// The multipliers of `solution` of `model` with laws with memory (module documentation).
pub(crate) fn floquet(
    model: &Model,
    solution: &Solution,
    options: &FloquetOptions,
) -> Result<Floquet> {
    if !available(model) {
        let element = model.memory_element().map_or("", |e| e.name());
        return Err(Error::MemoryUnsupported {
            analysis: format!(
                "stability of a free-free model or one over {MAX_DOFS} DOFs (finite differences on the time-domain model)"
            ),
            element: element.to_string(),
        });
    }
    let basis = solution.basis();
    check_cost(model, solution)?;
    let map = PeriodMap::new(
        model,
        basis.omega(),
        basis.subharmonic(),
        options.rtol.min(1e-10),
    )?;
    let map = Budgeted {
        map,
        used: std::cell::Cell::new(0),
    };
    let hb = crate::stability::hb_state::hb_start(solution);
    let mut x = hb.clone();
    x.extend(march(model, solution, map.map.laws()));
    let scales = scales(model, solution, map.map.laws());
    let (mut steps, mut polished) = (0, false);
    let mut best = f64::INFINITY;
    for _ in 0..MAX_NEWTON {
        let (px, s) = map.apply(&x)?;
        steps += s;
        let r: Vec<f64> = px.iter().zip(&x).map(|(p, x)| p - x).collect();
        let error = max_scaled(&r, &scales);
        if error < CONVERGED || (error < NOISE && error > 0.5 * best) {
            polished = true;
            break;
        }
        best = best.min(error);
        let (j, s) = jacobian(&map, &x, Some(&px), &scales)?;
        steps += s;
        // Least squares: a slider that sticks all period leaves a zero row in J - I (its
        // state is any), which the step leaves alone.
        let a = j - DMatrix::identity(x.len(), x.len());
        let rhs = DVector::from_iterator(r.len(), r.iter().map(|v| -v));
        let Ok(delta) = a.svd(true, true).solve(&rhs, 1e-10) else {
            break;
        };
        x.iter_mut().zip(delta.iter()).for_each(|(x, d)| *x += d);
    }
    if !polished {
        // The budget spent: polished if the map's noise is all that is left.
        let (px, s) = map.apply(&x)?;
        steps += s;
        let r: Vec<f64> = px.iter().zip(&x).map(|(p, x)| p - x).collect();
        polished = max_scaled(&r, &scales) < NOISE;
    }
    let (j, s) = jacobian(&map, &x, None, &scales)?;
    steps += s;
    let mut multipliers: Vec<Complex64> = j.complex_eigenvalues().iter().copied().collect();
    if multipliers
        .iter()
        .any(|m| !(m.re.is_finite() && m.im.is_finite()))
    {
        return Err(Error::NonFinite {
            what: "a Floquet multiplier of the time-domain model with memory".into(),
        });
    }
    multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    let orbit_correction = max_scaled(
        &x.iter().zip(&hb).map(|(a, b)| a - b).collect::<Vec<_>>(),
        &scales[..hb.len()],
    );
    let distance = orbit_distance(model, solution, &hb, &x[..hb.len()]);
    Ok(Floquet {
        multipliers,
        neutral: 0,
        orbit_correction,
        polished,
        orbit_start: x[..hb.len()].to_vec(),
        steps,
        reduction: None,
        orbit: Orbit::Exact,
        orbit_difference: None,
        orbit_distance: distance,
        // The multipliers are those of the orbit found (no HB orbit's own to fall back on).
        other_orbit: None,
    })
}

/// Most integrator steps the shooting's period maps may take together (about 10 s for a small
/// model with several laws): beyond, the model is too stiff for their
/// explicit integration, refused before any of it where the a priori bound exceeds it
/// ([`check_cost`]) and stopped where the steps taken do ([`Budgeted`]).
const MAX_STEPS: f64 = 1e6;

/// The period map with the steps taken so far, stopped past [`MAX_STEPS`].
struct Budgeted<'m> {
    map: PeriodMap<'m>,
    used: std::cell::Cell<usize>,
}

impl Budgeted<'_> {
    /// [`PeriodMap::apply`], or an error once the steps taken exceed [`MAX_STEPS`].
    fn apply(&self, x: &[f64]) -> Result<(Vec<f64>, usize)> {
        let (px, steps) = self.map.apply(x)?;
        self.used.set(self.used.get() + steps);
        if self.used.get() as f64 > MAX_STEPS {
            return Err(Error::TimeIntegration {
                reason: format!(
                    "the shooting of laws with memory stopped after {} steps of its period maps (the limit {MAX_STEPS:.0e}): the orbit is too fast or too unstable for their explicit integration; check the damping, stiffness and loads for a unit mistake, or skip the stability (--no-stability)",
                    self.used.get()
                ),
            });
        }
        Ok((px, steps))
    }
}

/// Refuses a model too stiff for the explicit integration of the period map before any of it:
/// DOP853 is stable for steps up to about `5/λ`, `λ` the fastest rate of the model along the
/// orbit (Gershgorin's bound `max_i Σ_j |D_ij| / M_ii + (Σ_j |K_ij| / M_ii)^½` with every
/// element at its largest tangent `|∂f/∂u|`, `|∂f/∂u̇|` on the HB orbit), so one period takes
/// at least `λ νT / 5` steps, and the multipliers alone `2(2n + s) + 1` periods.
fn check_cost(model: &Model, solution: &Solution) -> Result<()> {
    let Some(rate) = crate::stability::linear_rate::fastest_rate(model, solution) else {
        return Ok(());
    };
    let states: usize = model
        .elements()
        .iter()
        .filter_map(|e| e.law().memory().map(|m| m.state_len()))
        .sum();
    let periods = (2 * (2 * model.n_dofs() + states) + 1) as f64;
    let period = solution.basis().period();
    let steps = rate * period / 5.0 * periods;
    if steps <= MAX_STEPS {
        return Ok(());
    }
    Err(Error::TooLarge {
        what: "the stability of laws with memory (shooting on the time-domain model)".into(),
        size: format!("{steps:.1e} integrator steps"),
        limit: format!("{MAX_STEPS:.0e}"),
        advice: format!(
            "the fastest motion along the orbit decays or turns at {rate:.1e} 1/s, stiff for the explicit integration over periods of {period:.2e} s: check the damping, stiffness and loads for a unit mistake, or skip the stability (--no-stability)"
        ),
    })
}

/// `true` if the shooting of laws with memory applies to `model` (up to [`MAX_DOFS`] DOFs, no rigid-body mode:
/// their neutral multipliers 1 are not set apart from a sticking slider's).
pub fn available(model: &Model) -> bool {
    model.n_dofs() <= MAX_DOFS && rigid_body_modes(&Coordinates::full(model)).modes.ncols() == 0
}

/// `∂P/∂x` at `x` by forward differences from `P(x) = px`, or by central ones without it; and
/// the integrator's steps.
fn jacobian(
    map: &Budgeted,
    x: &[f64],
    px: Option<&[f64]>,
    scales: &[f64],
) -> Result<(DMatrix<f64>, usize)> {
    let m = x.len();
    let mut j = DMatrix::zeros(m, m);
    let mut steps = 0;
    let mut xe = x.to_vec();
    for c in 0..m {
        let h = STEP * scales[c];
        xe[c] = x[c] + h;
        let (plus, s) = map.apply(&xe)?;
        steps += s;
        let column: Vec<f64> = match px {
            Some(px) => plus.iter().zip(px).map(|(a, b)| (a - b) / h).collect(),
            None => {
                xe[c] = x[c] - h;
                let (minus, s) = map.apply(&xe)?;
                steps += s;
                plus.iter()
                    .zip(&minus)
                    .map(|(a, b)| (a - b) / (2.0 * h))
                    .collect()
            }
        };
        xe[c] = x[c];
        j.set_column(c, &DVector::from_vec(column));
    }
    Ok((j, steps))
}

/// The laws' states at `θ = 0` on the HB orbit: marched from the virgin state along
/// [`MARCH_SAMPLES`] samples per period, pass after pass until the state at the start of a
/// pass repeats (at most 50 passes).
fn march(model: &Model, solution: &Solution, laws: &[(usize, usize)]) -> Vec<f64> {
    let basis = solution.basis();
    let samples = MARCH_SAMPLES.max(8 * basis.harmonics());
    let nu = basis.subharmonic() as f64;
    let mut out = Vec::new();
    for &(e, len) in laws {
        let element = &model.elements()[e];
        let Some(memory) = element.law().memory() else {
            continue;
        };
        let path: Vec<(f64, f64, f64)> = (0..samples)
            .map(|j| {
                let theta = TAU * j as f64 / samples as f64;
                let u = element
                    .weights()
                    .iter()
                    .map(|&(i, w)| w * solution.displacement(i, theta));
                let du = element
                    .weights()
                    .iter()
                    .map(|&(i, w)| w * solution.velocity(i, theta));
                ((nu * theta) % TAU, u.sum(), du.sum())
            })
            .collect();
        let mut state = [0.0; crate::force::MAX_STATE];
        memory.initial_state(&mut state[..len]);
        for _ in 0..50 {
            let start = state;
            // The state at θ = 0 of the next pass is the one after the last sample, stepped to
            // the first sample of the next pass.
            for &(theta, u, du) in path.iter().skip(1).chain(path.first()) {
                memory.step(theta, u, du, &mut state[..len]);
            }
            let scale = state
                .iter()
                .chain(&start)
                .fold(1e-300_f64, |m, v| m.max(v.abs()));
            if state
                .iter()
                .zip(&start)
                .all(|(a, b)| (a - b).abs() <= 1e-13 * scale)
            {
                break;
            }
        }
        out.extend_from_slice(&state[..len]);
    }
    out
}

/// The scales `s_i` of `(q, q̇, s)` on the HB orbit, floored at 1e-9 of the largest of their
/// kind.
fn scales(model: &Model, solution: &Solution, laws: &[(usize, usize)]) -> Vec<f64> {
    let n = model.n_dofs();
    let h = solution.basis().harmonics();
    let w = solution.basis().fundamental();
    let q = solution.max_abs_all();
    let v: Vec<f64> = (0..n)
        .map(|i| {
            (1..=h)
                .map(|k| k as f64 * w * solution.harmonic(i, k).norm())
                .sum()
        })
        .collect();
    let s: Vec<f64> = laws
        .iter()
        .flat_map(|&(e, len)| {
            let element = &model.elements()[e];
            let u: f64 = element
                .weights()
                .iter()
                .map(|&(i, wi)| wi.abs() * q[i])
                .sum();
            std::iter::repeat_n(u, len)
        })
        .collect();
    let floor = |xs: Vec<f64>| -> Vec<f64> {
        let top = xs.iter().fold(0.0_f64, |m, v| m.max(*v));
        let top = if top > 0.0 { top } else { 1.0 };
        xs.into_iter().map(|x| x.max(1e-9 * top)).collect()
    };
    let mut out = floor(q);
    out.extend(floor(v));
    out.extend(floor(s));
    out
}

/// `max_i |r_i| / s_i`.
fn max_scaled(r: &[f64], scales: &[f64]) -> f64 {
    r.iter()
        .zip(scales)
        .map(|(r, s)| r.abs() / s)
        .fold(0.0, f64::max)
}
