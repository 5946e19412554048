//! Errors per quantity: what an engineer reads off a solution, each against its own scale.
//!
//! A relative norm over all DOFs is dominated by the largest of them: the static wind-up of
//! a drivetrain (radians) hides an error of its transmission error (micrometres). Here every
//! quantity `x` is compared on its own, by its *dynamic part* (its mean removed, so neither
//! the static offset nor a free-free model's rigid-body angle counts), relative to its own
//! peak-to-peak range:
//!
//! `e_x = max_j |(x_a - x̄_a)(θ_j) - (x_b - x̄_b)(θ_j)| / max(x_b - min x_b, 1e-6 |x̄_b|)`
//!
//! over `N` samples of the period, with `x_b` the reference (a reference without any range
//! is measured against `x_a`'s range instead). The quantities are every DOF,
//! every element coordinate `u = w·q` (a gear stage's transmission error) and every element
//! force `f(θ, u, u̇)` along the orbit (a mesh force; not for laws with memory). The samples
//! carry every harmonic of both arrays, so what the shorter one lacks counts.

use crate::error::Result;
use crate::harmonic::{AftPlan, HarmonicBasis};
use crate::model::Model;
use num_complex::Complex64;

/// A quantity of a model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "index")]
pub enum Quantity {
    /// DOF `i`'s displacement.
    Dof(usize),
    /// Element `e`'s coordinate `u = w·q`.
    Coordinate(usize),
    /// Element `e`'s force `f(θ, u, u̇)`.
    Force(usize),
}

impl Quantity {
    /// Its name in `model`: the DOF's name, `u(element)` or `f(element)`.
    pub fn name(&self, model: &Model) -> String {
        let element = |e: usize| model.elements().get(e).map_or("?", |e| e.name());
        match *self {
            Quantity::Dof(i) => model
                .dof_names()
                .get(i)
                .cloned()
                .unwrap_or_else(|| format!("dof {i}")),
            Quantity::Coordinate(e) => format!("u({})", element(e)),
            Quantity::Force(e) => format!("f({})", element(e)),
        }
    }

    /// `true` for a DOF or an element coordinate (what automatic harmonics control by
    /// default), `false` for a force.
    pub fn is_motion(&self) -> bool {
        !matches!(self, Quantity::Force(_))
    }
}

/// The error of one quantity (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct QuantityError {
    /// The quantity.
    pub quantity: Quantity,
    /// Its error relative to its range.
    pub error: f64,
    /// Its peak-to-peak range in the reference (the scale of `error`).
    pub range: f64,
}

/// The errors of every quantity of `model` between the harmonics `a` and the reference `b`
/// (harmonic-major, either may be shorter than the other), both on the fundamental and
/// period multiple of `basis`, sampled at `samples` points (at least 4 times the longer's
/// harmonics). Quantities without range and without difference are left out.
pub fn quantity_errors(
    model: &Model,
    basis: &HarmonicBasis,
    a: &[Complex64],
    b: &[Complex64],
    samples: usize,
) -> Result<Vec<QuantityError>> {
    let n = model.n_dofs();
    let h = (a.len().max(b.len()) / n.max(1)).saturating_sub(1).max(1);
    let plan_basis = HarmonicBasis::new(basis.omega(), h)?
        .with_subharmonic(basis.subharmonic())?
        .with_samples(samples.max(4 * h + 1))?;
    let plan = AftPlan::new(plan_basis);
    let mut scratch = plan.make_scratch();
    let omega = plan_basis.fundamental();
    let len = plan_basis.samples();
    let mut harmonics = vec![Complex64::default(); h + 1];
    let mut synth = |x: &[Complex64], gather: &dyn Fn(&[Complex64]) -> Complex64, rate: bool| {
        for (k, c) in harmonics.iter_mut().enumerate() {
            *c = x
                .get(k * n..(k + 1) * n)
                .map_or(Complex64::default(), gather);
        }
        let mut out = vec![0.0; len];
        let scale = |k: usize| {
            if rate {
                Complex64::new(0.0, k as f64 * omega)
            } else {
                Complex64::new(1.0, 0.0)
            }
        };
        plan.synthesize_into(&harmonics, scale, &mut out, &mut scratch);
        out
    };
    let mut out = Vec::new();
    for i in 0..n {
        let pick = move |q: &[Complex64]| q[i];
        out.extend(error_of(
            Quantity::Dof(i),
            &synth(a, &pick, false),
            &synth(b, &pick, false),
        ));
    }
    let thetas: Vec<f64> = (0..len).map(|j| plan_basis.shaft_angle(j)).collect();
    for (index, e) in model.elements().iter().enumerate() {
        let gather = |q: &[Complex64]| e.gather(q);
        let (ua, ub) = (synth(a, &gather, false), synth(b, &gather, false));
        out.extend(error_of(Quantity::Coordinate(index), &ua, &ub));
        if e.law().memory().is_some() || e.law().is_linear_time_invariant() {
            continue;
        }
        let (va, vb) = (synth(a, &gather, true), synth(b, &gather, true));
        let (mut fa, mut fb) = (vec![0.0; len], vec![0.0; len]);
        e.law().force_batch(&thetas, &ua, &va, &mut fa);
        e.law().force_batch(&thetas, &ub, &vb, &mut fb);
        out.extend(error_of(Quantity::Force(index), &fa, &fb));
    }
    Ok(out)
}

/// The error of `quantity` with samples `a` against the reference `b` (module
/// documentation); `None` if it has neither range nor difference.
fn error_of(quantity: Quantity, a: &[f64], b: &[f64]) -> Option<QuantityError> {
    let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len().max(1) as f64;
    let (ma, mb) = (mean(a), mean(b));
    let (lo, hi) = b
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, m), &x| {
            (l.min(x), m.max(x))
        });
    let range = hi - lo;
    let scale = range.max(1e-6 * mb.abs());
    let diff = a
        .iter()
        .zip(b)
        .map(|(x, y)| ((x - ma) - (y - mb)).abs())
        .fold(0.0, f64::max);
    if scale == 0.0 && diff == 0.0 {
        return None;
    }
    // A reference without range (a contact that never closes in it) against a moving `a`:
    // `a`'s own range is the scale, so the error is between 1/2 and 1 ("wrong by its whole
    // size"), finite, never 0/0 or infinity in a document.
    let scale = if scale > 0.0 {
        scale
    } else {
        let (lo, hi) = a
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, m), &x| {
                (l.min(x), m.max(x))
            });
        hi - lo
    };
    Some(QuantityError {
        quantity,
        error: diff / scale,
        range,
    })
}

/// The largest error among `errors` whose quantity passes `keep`.
pub fn worst(errors: &[QuantityError], keep: impl Fn(&Quantity) -> bool) -> Option<QuantityError> {
    errors
        .iter()
        .filter(|e| keep(&e.quantity))
        .copied()
        .max_by(|x, y| x.error.total_cmp(&y.error))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_without_range_is_measured_by_the_other_range() {
        // The reference's contact never closes (force 0); the approximation's swings ±2.
        let b = [0.0; 8];
        let a = [0.0, 2.0, 0.0, -2.0, 0.0, 2.0, 0.0, -2.0];
        let e = error_of(Quantity::Force(0), &a, &b).expect("a difference");
        assert_eq!(e.range, 0.0);
        // max |a - mean a| = 2 against a's range 4.
        assert_eq!(e.error, 0.5);
        // Both without range: nothing to report.
        assert!(error_of(Quantity::Force(0), &b, &b).is_none());
        // The ordinary case: a's dynamic part off by 0.1 on a range of 4.
        let c: Vec<f64> = a.iter().map(|x| 1.05 * x).collect();
        let e = error_of(Quantity::Dof(0), &c, &a).expect("a difference");
        assert!((e.error - 0.1 / 4.0).abs() < 1e-15, "{}", e.error);
    }
}
