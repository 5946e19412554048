//! The shooting's iteration on the orbit's start `x₀`: Newton–chord steps
//! `x̃₀ ← x̃₀ - (J - I)⁻¹ r̃(x₀)`, `r̃ = S⁻¹ (φ_T(x₀) - x₀)`, the step orthogonal to the
//! rigid-body positions.
//!
//! Newton takes `J = Φ̃(x₀)`, the monodromy matrix of the orbit from `x₀` itself. The chord
//! method keeps a `J` of a nearby orbit (the previous point of a sweep, or the last Newton
//! step) and converges linearly, at the rate `‖(J - I)⁻¹ (Φ̃ - J)‖`: a point of a sweep moves
//! its orbit little, and a pass of the exponential flow without its monodromy matrix costs a
//! fraction of one with it ([`record`](crate::stability::exponential::record)). A chord step that does not reduce the
//! scaled residual by [`CHORD_RATE`] is not counted against
//! [`FloquetOptions::max_shooting`] and is followed by a Newton step (its `J` kept for the next
//! chord steps); a chord step longer than `AHEAD_GAIN` times the residual (a kept `J` near a
//! singular one) is replaced by a Newton step at once. The Runge–Kutta flow, whose monodromy matrix comes with every pass, and the
//! comparison of the reduction's estimate ([`Goal::Compare`], which reads the multipliers of
//! every iterate) take Newton steps only.
//!
//! Whatever the steps, the iteration stops where Newton shooting did: converged at a scaled
//! residual `‖r̃‖∞ <= 10 rtol` (polished), or when a Newton step gains less than a half or the
//! budget is spent (polished if `‖r̃‖∞ <= 1e3 rtol`); the multipliers are those of the monodromy
//! matrix of the final orbit, formed for it.

use super::shoot::Goal;
use crate::error::Result;
use crate::stability::distance;
use crate::stability::exponential::integration::Integration;
use crate::stability::system::Coordinates;
use crate::stability::FloquetOptions;
use nalgebra::{DMatrix, DVector, Dyn, SVD};
use num_complex::Complex64;

/// A chord step must reduce the scaled residual at least by this factor.
pub(crate) const CHORD_RATE: f64 = 0.25;

/// The Newton step ahead of a converged orbit ([`Outcome::ahead`]) and a chord step are taken
/// up to this many times the residual (at most 9 along the drivetrain's run-up; 10⁷ at a
/// period doubling, where `Φ̃ - I` is nearly singular).
const AHEAD_GAIN: f64 = 100.0;

/// A scaled monodromy matrix kept for the chord steps of a later shooting, with the scales
/// `(s_q, s_v)` and the coordinates it was formed in.
#[derive(Debug, Clone)]
pub(crate) struct KeptJacobian {
    phi: DMatrix<f64>,
    scales: (f64, f64),
    dofs: usize,
    basis: Option<DMatrix<f64>>,
}

impl KeptJacobian {
    pub(crate) fn new(phi: DMatrix<f64>, sys: &Coordinates, scales: (f64, f64)) -> Self {
        Self {
            phi,
            scales,
            dofs: sys.model.n_dofs(),
            basis: sys.basis.clone(),
        }
    }

    /// `Φ̃` in the scales `(s_q, s_v)` if it was formed in the coordinates `sys` or in nearly
    /// the same ones: with `Φ̃ = S⁻¹ Φ S`, `S = diag(s_q I, s_v I)`, entry `(i, j)` times
    /// `(s_i/s'_i) (s'_j/s_j)`. A sweep's reduced bases differ from point to point (the
    /// attachment modes are static responses at a shift that follows the cut-off, which
    /// follows Ω): a basis within 1 % (largest entry) still gives a chord Jacobian, which
    /// need only be near.
    pub(crate) fn in_scales(&self, sys: &Coordinates, scales: (f64, f64)) -> Option<DMatrix<f64>> {
        let n = sys.len();
        let near = match (&self.basis, &sys.basis) {
            (None, None) => true,
            (Some(a), Some(b)) if a.shape() == b.shape() => {
                (a - b).amax() <= 1e-2 * a.amax().max(b.amax())
            }
            _ => false,
        };
        if self.phi.nrows() != 2 * n || self.dofs != sys.model.n_dofs() || !near {
            return None;
        }
        let old = |i: usize| if i < n { self.scales.0 } else { self.scales.1 };
        let new = |i: usize| if i < n { scales.0 } else { scales.1 };
        let phi = DMatrix::from_fn(2 * n, 2 * n, |i, j| {
            self.phi[(i, j)] * (old(i) / new(i)) * (new(j) / old(j))
        });
        phi.iter().all(|v| v.is_finite()).then_some(phi)
    }
}

/// What the iteration works with.
pub(crate) struct Problem<'a> {
    /// `(s_q, s_v)`.
    pub(crate) scales: (f64, f64),
    /// Excitation periods per orbit (`ν`).
    pub(crate) periods: usize,
    /// An orthonormal basis of the states without rigid-body positions (the steps' span).
    pub(crate) free_positions: &'a DMatrix<f64>,
    /// The multipliers of a scaled monodromy matrix.
    pub(crate) multipliers_of: &'a dyn Fn(&DMatrix<f64>) -> Vec<Complex64>,
    pub(crate) options: &'a FloquetOptions,
    pub(crate) goal: Goal<'a>,
}

/// Where the iteration stopped.
pub(crate) struct Outcome {
    /// `Φ̃` of the final orbit.
    pub(crate) phi: DMatrix<f64>,
    pub(crate) polished: bool,
    /// Converged and well-conditioned: one more Newton step from the final orbit (`(q, q̇)` in
    /// the coordinates), the best guess of the periodic orbit's start for the next point of a
    /// sweep.
    pub(crate) ahead: Option<Vec<f64>>,
    /// The sensitivity of the multipliers ([`Shot::kappa`](super::shoot::Shot::kappa)),
    /// measured when the first step was a Newton step.
    pub(crate) kappa: Option<f64>,
    /// Steps of flows given up for the Runge–Kutta flow.
    pub(crate) earlier_steps: usize,
}

/// `J` with the SVD of `(J - I) P` (`P` the free positions).
struct Factored {
    phi: DMatrix<f64>,
    svd: SVD<f64, Dyn, Dyn>,
    tol: f64,
}

impl Factored {
    fn new(phi: DMatrix<f64>, free_positions: &DMatrix<f64>) -> Self {
        let s2 = phi.nrows();
        let a = (&phi - DMatrix::<f64>::identity(s2, s2)) * free_positions;
        let svd = a.svd(true, true);
        let tol = 1e-13 * svd.singular_values.max();
        Self { phi, svd, tol }
    }
}

/// `Φ̃` of the last pass: `known` where it came with the pass, else the flow's (computed now).
fn pass_monodromy(
    known: Option<DMatrix<f64>>,
    flow: &mut Integration<'_, '_>,
) -> Result<DMatrix<f64>> {
    match known {
        Some(phi) => Ok(phi),
        None => flow.monodromy(),
    }
}

/// Iterates `x0` (`(q, q̇)` in the coordinates) to the periodic orbit with the flow `flow`
/// (replaced by `runge_kutta()` where the exponential flow meets a law that is not affine),
/// starting the chord steps with `jacobian` if given.
/// The monodromy matrices of the exponential flow are multiplied on a second thread where
/// there is one ([`pipeline`](crate::stability::exponential::pipeline)).
pub(crate) fn iterate<'c, 'm>(
    problem: &Problem,
    flow: &mut Integration<'c, 'm>,
    runge_kutta: &dyn Fn() -> Result<Integration<'c, 'm>>,
    x0: &mut [f64],
    jacobian: Option<DMatrix<f64>>,
) -> Result<Outcome> {
    flow.with_assembler(|flow| iterate_with(problem, flow, runge_kutta, x0, jacobian))
}

fn iterate_with<'c, 'm>(
    problem: &Problem,
    flow: &mut Integration<'c, 'm>,
    runge_kutta: &dyn Fn() -> Result<Integration<'c, 'm>>,
    x0: &mut [f64],
    jacobian: Option<DMatrix<f64>>,
) -> Result<Outcome> {
    let s2 = x0.len();
    let (scale_q, scale_v) = problem.scales;
    let scale = |i: usize| if i < s2 / 2 { scale_q } else { scale_v };
    let rtol = problem.options.rtol;
    let exact = matches!(problem.goal, Goal::Exact);
    let free = problem.free_positions;
    let mut kept = jacobian
        .filter(|_| exact)
        .map(|phi| Factored::new(phi, free));
    let mut x_end = vec![0.0; s2];
    let mut first: Option<(Vec<Complex64>, f64)> = None;
    let mut kappa = None;
    let mut last_residual = f64::INFINITY;
    // Steps taken, and those counted against the budget.
    let (mut iteration, mut counted) = (0, 0);
    let mut chord = false;
    let mut earlier_steps = 0;
    let mut polished = false;
    let mut ahead = None;
    let phi = loop {
        x_end.copy_from_slice(x0);
        if !flow.pass(&mut x_end, problem.periods)? {
            // A law bent inside a piece: the Runge–Kutta flow from the same start.
            earlier_steps += flow.steps();
            *flow = runge_kutta()?;
            continue;
        }
        // Φ̃ of this orbit where it is already known.
        let mut current = flow.free_monodromy();
        let r = DVector::from_fn(s2, |i, _| (x_end[i] - x0[i]) / scale(i));
        let res = r.amax();
        if let (1, Some((mu, step))) = (iteration, &first) {
            let phi = pass_monodromy(current.take(), flow)?;
            kappa = Some(distance(mu, &(problem.multipliers_of)(&phi)) / step);
            current = Some(phi);
        }
        // Converged to the integration noise, or Newton has stalled there.
        let stop = if res <= 10.0 * rtol {
            polished = true;
            true
        } else if !res.is_finite() {
            true
        } else if chord && res > CHORD_RATE * last_residual {
            // A stale Jacobian: the step is not counted, and the next one is Newton's.
            kept = None;
            counted -= 1;
            false
        } else if counted >= problem.options.max_shooting || res >= 0.5 * last_residual {
            polished = res <= 1e3 * rtol;
            true
        } else {
            false
        };
        if stop {
            let phi = pass_monodromy(current, flow)?;
            if !polished {
                break phi;
            }
            // A start for the next point: one more Newton step from the converged orbit, with
            // its own Φ̃ (not integrated: the next shooting checks its residual), unless the
            // step is more than AHEAD_GAIN times the residual: near a bifurcation Φ̃ - I is
            // nearly singular, and the step would go anywhere along the critical direction
            // (towards another orbit, at a period doubling).
            let j = Factored::new(phi, free);
            if let Ok(z) = j.svd.solve(&(-&r), j.tol) {
                let delta = free * z;
                if delta.amax() <= AHEAD_GAIN * res {
                    ahead = Some((0..s2).map(|i| x0[i] + delta[i] * scale(i)).collect());
                }
            }
            break j.phi;
        }
        last_residual = res;
        iteration += 1;
        counted += 1;
        let mut fresh = current.is_some() || kept.is_none();
        if fresh {
            let phi = pass_monodromy(current.take(), flow)?;
            kept = Some(Factored::new(phi, free));
        }
        // (J - I) δ̃ = -r̃ with δ̃ orthogonal to rigid-body positions.
        let solve = |j: &Factored| j.svd.solve(&(-&r), j.tol).ok().map(|z| free * z);
        let mut delta = solve(kept.as_ref().expect("a Jacobian"));
        if !fresh && delta.as_ref().is_none_or(|d| d.amax() > AHEAD_GAIN * res) {
            // A kept Jacobian that is nearly singular (a bifurcation near): Newton instead.
            kept = Some(Factored::new(flow.monodromy()?, free));
            fresh = true;
            delta = solve(kept.as_ref().expect("a Jacobian"));
        }
        chord = !fresh;
        let j = kept.as_ref().expect("a Jacobian");
        let Some(delta) = delta else {
            break j.phi.clone();
        };
        let step = delta.amax();
        if iteration == 1 && fresh && exact {
            first = Some(((problem.multipliers_of)(&j.phi), step));
        }
        if let Goal::Compare { reference, kappa } = problem.goal {
            // Newton steps only: `J` is this orbit's.
            if kappa * step <= 0.01 * distance(reference, &(problem.multipliers_of)(&j.phi)) {
                break j.phi.clone();
            }
        }
        for i in 0..s2 {
            x0[i] += delta[i] * scale(i);
        }
    };
    Ok(Outcome {
        phi,
        polished,
        ahead,
        kappa,
        earlier_steps,
    })
}
