//! The HB orbit's state at `t = 0` and how far another state lies from it: where every
//! shooting starts, and how the orbit it found is told from the HB solution's.

use crate::model::Model;
use crate::solution::Solution;

/// The HB state `(q(0), q̇(0))` in the model's DOFs: `q_i(0) = Σ_k Re Q_ik`,
/// `q̇_i(0) = -Σ_k k ω Im Q_ik` (`ω` the fundamental), the same sums as
/// [`Solution::displacement`] and [`Solution::velocity`] at `θ = 0` without their rotations.
pub(crate) fn hb_start(solution: &Solution) -> Vec<f64> {
    let n = solution.dof_names().len();
    let h = solution.basis().harmonics();
    let w = solution.basis().fundamental();
    let q = (0..n).map(|i| (0..=h).map(|k| solution.harmonic(i, k).re).sum::<f64>());
    let v = (0..n).map(|i| {
        (1..=h)
            .map(|k| -(solution.harmonic(i, k).im * (k as f64 * w)))
            .sum::<f64>()
    });
    q.chain(v).collect()
}

/// A shooting whose orbit starts farther than this ([`orbit_distance`]) from the HB state has
/// found another periodic orbit than the HB solution's.
pub const OTHER_ORBIT_DISTANCE: f64 = 5e-3;

/// How far the state `x = (q, q̇)` (the model's DOFs) lies from the HB orbit's state at `t = 0`
/// (`hb`), in positions: the largest of
///
/// * `|q_i − q_i*| / A`, `A = max_i Σ_{k≥1} |Q_ik|` the largest dynamic amplitude of a DOF
///   (static wind-up and the rigid-body position do not count), and
/// * for every element that is not linear in the state (contacts, stops, nonlinear springs),
///   `|w·(q − q*)| / A_e`, `A_e = Σ_{k≥1} |w·Q_k|` its own dynamic amplitude (at least 1e-3 of
///   `Σ|w_i| A`: an element that hardly moves is judged by the DOFs' range).
///
/// Velocities are left out: the HB velocity converges slowest where a stiffness jumps.
pub fn orbit_distance(model: &Model, solution: &Solution, hb: &[f64], x: &[f64]) -> f64 {
    let n = model.n_dofs();
    if !x.iter().chain(hb).all(|v| v.is_finite()) {
        return f64::INFINITY;
    }
    let h = solution.basis().harmonics();
    let dynamic = |i: usize| (1..=h).map(|k| solution.harmonic(i, k).norm()).sum::<f64>();
    let largest = (0..n).map(dynamic).fold(0.0, f64::max);
    let statics = (0..n)
        .map(|i| solution.harmonic(i, 0).norm())
        .fold(0.0, f64::max);
    // A solution at rest: judged against its static size (or absolutely).
    let a = if largest > 0.0 {
        largest
    } else if statics > 0.0 {
        1e-6 * statics
    } else {
        1.0
    };
    let dofs = (0..n).map(|i| (x[i] - hb[i]).abs() / a).fold(0.0, f64::max);
    let elements = model
        .elements()
        .iter()
        .filter(|e| !(e.law().is_linear_in_state() || e.law().is_linear_time_invariant()))
        .map(|e| {
            let w = e.weights();
            let own: f64 = (1..=h)
                .map(|k| {
                    w.iter()
                        .map(|&(i, c)| solution.harmonic(i, k) * c)
                        .sum::<num_complex::Complex64>()
                        .norm()
                })
                .sum();
            let floor = 1e-3 * a * w.iter().map(|&(_, c)| c.abs()).sum::<f64>();
            let du: f64 = w.iter().map(|&(i, c)| c * (x[i] - hb[i])).sum();
            du.abs() / own.max(floor).max(f64::MIN_POSITIVE)
        })
        .fold(0.0, f64::max);
    let d = dofs.max(elements);
    if d.is_finite() {
        d
    } else {
        f64::INFINITY
    }
}
