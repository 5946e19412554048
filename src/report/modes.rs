//! Natural frequencies and mode shapes of the model linearised about an orbit, with the bounds
//! a time-varying mesh stiffness puts on them: the inputs of a Campbell diagram.
//!
//! Each element contributes its tangent stiffness `k_e(θ) = ∂f_e/∂u(θ, ū_e, 0)` at the mean
//! `ū_e` of its coordinate on a periodic solution (the loaded flank of a contact), sampled over
//! the period. Three stiffness matrices follow,
//!
//! `K_mean = K + Σ_e k̄_e w_e w_eᵀ`, `K_low = K + Σ_e min_θ k_e w_e w_eᵀ`,
//! `K_high = K + Σ_e max_θ k_e w_e w_eᵀ`
//!
//! (for a rectangular mesh stiffness: the mean, one-tooth and two-tooth contact), and the
//! undamped modes `K φ = ω² M φ` of each ([`crate::stability`]'s eigen solver: dense up to 300
//! DOFs, shift-invert subspace iteration above). A mode below `1e-6` of the highest frequency
//! found is a rigid-body mode (0 Hz) of a free-free model.

use crate::model::Model;
use crate::solution::Solution;
use crate::Result;
use nalgebra::DMatrix;
use std::f64::consts::TAU;

/// Samples of the period for the stiffness range.
const SAMPLES: usize = 256;

/// Natural frequencies (Hz, ascending) with the mean stiffness and its bounds, and the mode
/// shapes of the mean (columns, mass-normalised, `n × modes`).
#[derive(Debug, Clone)]
pub struct NaturalFrequencies {
    /// With every element at its mean tangent stiffness.
    pub mean: Vec<f64>,
    /// With every element at its smallest stiffness over the period (one-tooth contact).
    pub lower: Vec<f64>,
    /// With every element at its largest stiffness over the period (two-tooth contact).
    pub upper: Vec<f64>,
    /// Mode shapes of `mean` (columns).
    pub shapes: DMatrix<f64>,
    /// Rigid-body modes (0 Hz) among them.
    pub rigid: usize,
}

/// The natural frequencies of `model` linearised on the periodic solution `sol`, up to
/// `max_hz` (every mode of a model of at most 300 DOFs).
///
/// ```
/// use hbal::force::{LinearSpring, MeshDamping, MeshProfile, MeshStiffness};
/// use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
/// // A 1-DOF mesh: k between 1e4 (one tooth) and 2e4 (two teeth), mass 1.
/// let mesh = MeshStiffness::new(1, MeshProfile::Rectangular { one_tooth: 1e4, two_tooth: 2e4, contact_ratio: 1.5 }, MeshDamping::Constant(1.0));
/// let model = Model::builder(&["x"]).mass_diagonal(&[1.0]).element("mesh", &[("x", 1.0)], mesh).load("x", 1, 1.0, 0.0).build()?;
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(10.0, 16)?)?;
/// let sol = Newton::new().solve(&hb, &mut hb.workspace())?;
/// let f = hbal::report::natural_frequencies(&model, &sol, f64::INFINITY)?;
/// let hz = |k: f64| k.sqrt() / std::f64::consts::TAU;
/// assert!((f.lower[0] - hz(1e4)).abs() < 1e-9 && (f.upper[0] - hz(2e4)).abs() < 1e-9);
/// assert!((f.mean[0] - hz(1.5e4)).abs() < 1e-2 * hz(1.5e4));
/// # Ok::<(), hbal::Error>(())
/// ```
pub fn natural_frequencies(
    model: &Model,
    sol: &Solution,
    max_hz: f64,
) -> Result<NaturalFrequencies> {
    let n = model.n_dofs();
    let mean: Vec<f64> = sol.harmonics()[..n].iter().map(|q| q.re).collect();
    natural_frequencies_at(model, &mean, max_hz)
}

/// As [`natural_frequencies`], linearised at the mean coordinates `mean` (one per DOF)
/// instead of a solution's: for a model whose laws are all linear in the state any `mean`
/// gives the same frequencies, and no operating point is needed.
pub fn natural_frequencies_at(
    model: &Model,
    mean: &[f64],
    max_hz: f64,
) -> Result<NaturalFrequencies> {
    let n = model.n_dofs();
    if mean.len() != n {
        return Err(crate::Error::DimensionMismatch {
            context: "natural frequencies".into(),
            expected: format!("{n} mean coordinates"),
            got: mean.len().to_string(),
        });
    }
    let mut ranges = Vec::with_capacity(model.elements().len());
    for e in model.elements() {
        let mean_u = e.gather(mean);
        let (mut lo, mut hi, mut sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
        for j in 0..SAMPLES {
            let theta = TAU * j as f64 / SAMPLES as f64;
            let k = e.law().derivatives(theta, mean_u, 0.0).0;
            if !k.is_finite() {
                return Err(crate::Error::NonFinite {
                    what: format!("stiffness of element `{}` at its mean coordinate", e.name()),
                });
            }
            lo = lo.min(k);
            hi = hi.max(k);
            sum += k;
        }
        ranges.push((sum / SAMPLES as f64, lo, hi));
    }
    let stiffness = |pick: fn(&(f64, f64, f64)) -> f64| {
        model.structural_stiffness().plus_outer(
            model
                .elements()
                .iter()
                .zip(&ranges)
                .map(|(e, r)| (pick(r), e.weights())),
        )
    };
    let cutoff = if max_hz.is_finite() {
        (TAU * max_hz).powi(2)
    } else {
        f64::INFINITY
    };
    let solve = |k: &crate::model::SparseMatrix| -> Result<(Vec<f64>, DMatrix<f64>)> {
        // The shift makes a free-free model factorisable (its rigid modes come out at ~0).
        let scale = k.amax() / model.mass().amax().max(f64::MIN_POSITIVE);
        let (modes, _) = crate::stability::lowest_modes(k, model.mass(), cutoff, 1e-4 * scale)?;
        let hz = modes
            .values
            .iter()
            .map(|l| l.max(0.0).sqrt() / TAU)
            .collect();
        Ok((hz, modes.vectors))
    };
    let (mut mean, shapes) = solve(&stiffness(|r| r.0))?;
    let (mut lower, _) = solve(&stiffness(|r| r.1))?;
    let (mut upper, _) = solve(&stiffness(|r| r.2))?;
    let top = mean.iter().cloned().fold(0.0, f64::max);
    let mut rigid = 0;
    for set in [&mut mean, &mut lower, &mut upper] {
        for f in set.iter_mut() {
            if *f < 1e-6 * top {
                *f = 0.0;
            }
        }
    }
    rigid += mean.iter().filter(|f| **f == 0.0).count();
    Ok(NaturalFrequencies {
        mean,
        lower,
        upper,
        shapes,
        rigid,
    })
}
