//! Shooting and the monodromy matrix in given coordinates (the model's DOFs or a reduced basis,
//! [`Coordinates`]): `x₀ ← x₀ - (J - I)⁻¹ (φ_T(x₀) - x₀)` from the HB state at `t = 0`
//! (projected onto the coordinates) with Newton–chord steps ([`chord`](super::chord)), then
//! the multipliers of the final orbit's `Φ` without its neutral block.

use super::chord::{iterate, KeptJacobian, Outcome, Problem};
use crate::error::{Error, Result};
use crate::solution::Solution;
use crate::stability::exponential::affine;
use crate::stability::exponential::exp_flow::ExpFlow;
use crate::stability::exponential::integration::Integration;
use crate::stability::exponential::kept::KeptGenerators;
use crate::stability::hb_state::hb_start;
use crate::stability::integrated::flow::{Flow, FlowOptions};
use crate::stability::integrated::guide::Guide;
use crate::stability::neutral;
use crate::stability::scales::scales;
use crate::stability::system::Coordinates;
use crate::stability::{eigenvalues, Floquet, FloquetOptions, Integrator, Orbit};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Where the shooting starts.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Start<'a> {
    /// The HB state at `t = 0`.
    Hb,
    /// The HB state plus a correction `(δq, δq̇)` in the model's DOFs (a sweep's previous
    /// point's correction).
    Corrected(&'a [f64]),
    /// A state `(q, q̇)` in the model's DOFs (the exact orbit on another basis).
    State(&'a [f64]),
}

/// When the shooting stops.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Goal<'a> {
    /// At the exact periodic orbit (scaled residual below `10 rtol`).
    Exact,
    /// The comparison of the reduction's estimate: once the change of the multipliers that
    /// the next Newton step `δ̃` would bring, predicted as `κ ‖δ̃‖∞` with the sensitivity `κ`
    /// measured by the first analysis, is below 1 % of their distance to `reference`.
    Compare {
        reference: &'a [Complex64],
        kappa: f64,
    },
    /// No shooting: the multipliers of the HB orbit itself whatever the laws (with
    /// [`Orbit::Harmonic`]), from the exponential flow's pieces where they apply and the
    /// Runge–Kutta flow along the HB orbit ([`Guide`]) otherwise.
    Own,
}

/// A Floquet analysis and the sensitivity of its multipliers to the orbit's start: `κ` =
/// the [`distance`](crate::stability::distance) between the multipliers of the first two shooting iterations over the
/// first Newton step (`None` if the first period was already converged).
pub(crate) struct Shot {
    pub(crate) floquet: Floquet,
    pub(crate) kappa: Option<f64>,
    /// Converged: the next point's best guess of the orbit's start in the model's DOFs
    /// ([`Outcome::ahead`](super::chord::Outcome::ahead)).
    pub(crate) ahead: Option<Vec<f64>>,
    /// The scaled monodromy matrix of the final orbit, for the chord steps of the next point.
    pub(crate) jacobian: KeptJacobian,
}

/// The Floquet analysis of `solution` in the coordinates `sys`.
pub(crate) fn shoot(
    sys: &Coordinates,
    solution: &Solution,
    options: &FloquetOptions,
    start: Start,
    goal: Goal,
    jacobian: Option<&KeptJacobian>,
    kept: &mut KeptGenerators,
) -> Result<Shot> {
    let n_model = sys.model.n_dofs();
    let n = sys.len();
    let omega = solution.basis().omega();
    let h = solution.basis().harmonics();
    // The HB orbit's harmonics in these coordinates (real and imaginary parts projected).
    let harmonics: Vec<Complex64> = if sys.basis.is_none() {
        solution.harmonics()[..(h + 1) * n_model].to_vec()
    } else {
        // Columns (Re Q_k, Im Q_k), k = 0..=H, projected together.
        let all = solution.harmonics();
        let parts = DMatrix::from_fn(n_model, 2 * (h + 1), |i, c| {
            let z = all[(c / 2) * n_model + i];
            if c % 2 == 0 {
                z.re
            } else {
                z.im
            }
        });
        let p = sys.project(&parts);
        (0..(h + 1) * n)
            .map(|j| Complex64::new(p[(j % n, 2 * (j / n))], p[(j % n, 2 * (j / n) + 1)]))
            .collect()
    };
    let (scale_q, omega_max, amplitudes) = scales(sys, solution, &harmonics);
    let scale_v = scale_q * omega_max;
    let flow_options = || FlowOptions {
        rtol: options.rtol,
        h_max: 1.0 / omega_max,
        max_steps: options.max_steps,
    };
    let runge_kutta = || -> Result<Integration> {
        let flow = Flow::new(sys, omega, scale_q, scale_v, options.rtol)?;
        Ok(Integration::runge_kutta(flow, flow_options(), 2 * n))
    };
    let mut flow = if options.integrator == Integrator::Auto
        && affine::piecewise_affine(sys.model, &amplitudes)
    {
        Integration::exponential(ExpFlow::new(
            sys,
            (omega, scale_q, scale_v, omega_max),
            options.max_steps,
            std::mem::take(kept),
        )?)
    } else {
        runge_kutta()?
    };
    let s2 = 2 * n;
    // The HB state at t = 0 in the model's DOFs and in these coordinates.
    let x_hb = hb_start(solution);
    if x_hb.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "initial state of the Floquet analysis".into(),
        });
    }
    let usable = |s: &[f64]| s.len() == 2 * n_model && s.iter().all(|v| v.is_finite());
    let from: Vec<f64> = match start {
        Start::Corrected(d) if usable(d) => x_hb.iter().zip(d).map(|(a, b)| a + b).collect(),
        Start::State(s) if usable(s) => s.to_vec(),
        _ => x_hb.clone(),
    };
    let x0 = sys.project(&DMatrix::from_column_slice(n_model, 2, &from));
    let mut x0 = x0.as_slice().to_vec();
    let rigid = neutral::rigid_body_modes(sys);
    let (positions, all) = neutral::state_bases(&rigid);
    let free_positions = neutral::complement(&positions, s2);
    // The multipliers of Φ̃ without its neutral block.
    let w = (all.ncols() > 0).then(|| neutral::complement(&all, s2));
    let multipliers_of = |phi: &DMatrix<f64>| match &w {
        None => eigenvalues(phi),
        Some(w) => eigenvalues(&(w.transpose() * phi * w)),
    };
    let problem = Problem {
        scales: (scale_q, scale_v),
        periods: solution.basis().subharmonic(),
        free_positions: &free_positions,
        multipliers_of: &multipliers_of,
        options,
        goal,
    };
    let jacobian = jacobian.and_then(|j| j.in_scales(sys, (scale_q, scale_v)));
    // The HB orbit's own pieces: no integration, nothing to polish (unless a law turns out
    // not to be affine along it).
    let mut earlier_steps = 0;
    let along = match &mut flow {
        Integration::Exponential { flow, record } if options.orbit == Orbit::Harmonic => {
            let all = &solution.harmonics()[..(h + 1) * n_model];
            let basis = solution.basis();
            if flow.along_harmonics(all, basis.fundamental(), basis.subharmonic(), record)? {
                Some(flow.monodromy(record)?)
            } else {
                flow.integrate_from_here();
                None
            }
        }
        _ => None,
    };
    // Laws that are not piecewise affine: the Runge–Kutta flow along the HB orbit.
    let along = match along {
        None if matches!(goal, Goal::Own) && options.orbit == Orbit::Harmonic => {
            let fundamental = solution.basis().fundamental();
            let guide = Guide::new(&harmonics, n, fundamental);
            let guided = Flow::new(sys, omega, scale_q, scale_v, options.rtol)?.along(guide);
            let earlier = flow.steps();
            flow = Integration::runge_kutta(guided, flow_options(), 2 * n);
            let mut x = x0.clone();
            flow.pass(&mut x, solution.basis().subharmonic())?;
            earlier_steps = earlier;
            Some(flow.monodromy()?)
        }
        a => a,
    };
    let harmonic = along.is_some();
    let outcome = match along {
        Some(phi) => Outcome {
            phi,
            polished: false,
            ahead: None,
            kappa: None,
            earlier_steps,
        },
        None => iterate(&problem, &mut flow, &runge_kutta, &mut x0, jacobian)?,
    };
    *kept = flow.kept_generators();
    let phi = outcome.phi;
    // The exact orbit's start in the model's DOFs, against the HB state there.
    let lift = |x: &[f64]| {
        let mut out = sys.lift(&x[..n]);
        out.extend(sys.lift(&x[n..]));
        out
    };
    let orbit_start = lift(&x0);
    let ahead = outcome.ahead.as_deref().map(lift);
    let full_scale_q = if sys.basis.is_none() {
        scale_q
    } else {
        // An upper bound of max |q_i(t)|: max_i Σ_k |Q_ik|.
        let bound = (0..n_model)
            .map(|i| (0..=h).map(|k| solution.harmonic(i, k).norm()).sum::<f64>())
            .fold(0.0, f64::max);
        if bound > 0.0 && bound.is_finite() {
            bound
        } else {
            1.0
        }
    };
    let full_scale = |i: usize| {
        if i < n_model {
            full_scale_q
        } else {
            full_scale_q * omega_max
        }
    };
    // On a reduced basis, from the HB state's projection onto it: how far the shooting
    // moved, not what the basis cannot hold (the reduction's own error is its estimate's).
    let hb_here = if sys.basis.is_none() {
        x_hb.clone()
    } else {
        lift(
            sys.project(&DMatrix::from_column_slice(n_model, 2, &x_hb))
                .as_slice(),
        )
    };
    let orbit_distance = if harmonic {
        0.0
    } else {
        crate::stability::orbit_distance(sys.model, solution, &hb_here, &orbit_start)
    };
    let orbit_correction = (0..2 * n_model)
        .map(|i| (orbit_start[i] - hb_here[i]).abs() / full_scale(i))
        .fold(0.0, f64::max);
    let multipliers = multipliers_of(&phi);
    if multipliers
        .iter()
        .any(|m| !(m.re.is_finite() && m.im.is_finite()))
    {
        return Err(Error::NonFinite {
            what: "Floquet multipliers".into(),
        });
    }
    Ok(Shot {
        floquet: Floquet {
            multipliers,
            neutral: all.ncols(),
            orbit_correction,
            polished: outcome.polished,
            orbit_start,
            steps: outcome.earlier_steps + flow.steps(),
            reduction: None,
            orbit: if harmonic {
                Orbit::Harmonic
            } else {
                Orbit::Exact
            },
            orbit_difference: None,
            orbit_distance,
            other_orbit: None,
        },
        kappa: outcome.kappa,
        ahead,
        jacobian: KeptJacobian::new(phi, sys, (scale_q, scale_v)),
    })
}
