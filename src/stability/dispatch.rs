//! Which monodromy matrix: the dense one in the model's DOFs (`2n × 2n`, `O(n³)` per
//! integration step) or the one on a reduced basis ([`reduction`](super::reduction): the
//! modes below a cut-off plus attachment modes, `2(r + a) × 2(r + a)` whatever n), and the
//! reduction's accuracy estimate.

use super::reduction::reduced_basis;
use super::shooting::shoot;
use super::system::Coordinates;
use super::{Floquet, FloquetOptions};
use crate::error::{Error, Result};
use crate::model::Model;
use crate::solution::Solution;
use num_complex::Complex64;

/// How [`FloquetOptions::compute`] forms the monodromy matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FloquetMethod {
    /// Dense below [`FloquetMethod::REDUCED_FROM`] DOFs, reduced from there on.
    #[default]
    Auto,
    /// Dense in the model's DOFs (up to [`Model::MAX_DENSE_DOFS`]).
    Dense,
    /// On the reduced basis (modes below the cut-off and attachment modes).
    Reduced,
}

impl FloquetMethod {
    /// The smallest model that [`FloquetMethod::Auto`] reduces.
    pub const REDUCED_FROM: usize = 64;

    /// The method `self` means for `model` (`Auto` resolved).
    pub fn resolve(self, model: &Model) -> FloquetMethod {
        match self {
            FloquetMethod::Auto if model.n_dofs() >= Self::REDUCED_FROM => FloquetMethod::Reduced,
            FloquetMethod::Auto => FloquetMethod::Dense,
            m => m,
        }
    }
}

/// The reduced basis of a Floquet analysis and how far its multipliers can be trusted.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reduction {
    /// Size of the basis, `r + a` (the monodromy matrix is twice that square).
    pub dofs: usize,
    /// r, undamped modes kept (every mode below the cut-off).
    pub modes: usize,
    /// a, attachment modes (static responses to unit forces on the element coordinates and
    /// loaded DOFs, less those already in the span).
    pub attachment: usize,
    /// The cut-off ω_c in rad/s.
    pub cutoff: f64,
    /// The accuracy estimate: the largest distance `min_j |μ_i - μ'_j|` of the leading
    /// multipliers `μ_i` (modulus at least half the largest, at most 8) to those `μ'_j` on the
    /// basis with twice the cut-off (more if that adds no mode). `Some(0)` when the basis
    /// spans the whole space (a similarity transform: only the integrator's error is left);
    /// `None` when not estimated ([`FloquetOptions::estimate`]).
    #[serde(default)]
    pub estimate: Option<f64>,
    /// Size of the comparison basis of the estimate.
    #[serde(default)]
    pub comparison_dofs: Option<usize>,
}

impl FloquetOptions {
    /// Defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// These options with `method`.
    pub fn with_method(mut self, method: FloquetMethod) -> Self {
        self.method = method;
        self
    }

    /// The multipliers of the periodic orbit of `model` next to `solution`.
    pub fn compute(&self, model: &Model, solution: &Solution) -> Result<Floquet> {
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
        // The variational equation of a law with memory is not the one of `(∂f/∂u, ∂f/∂u̇)`:
        // refuse rather than give wrong multipliers.
        if let Some(e) = model.memory_element() {
            return Err(Error::MemoryUnsupported {
                analysis: "stability".into(),
                element: e.name().to_string(),
            });
        }
        let n = model.n_dofs();
        if solution.harmonics().len() < n || solution.dof_names().len() != n {
            return Err(Error::DimensionMismatch {
                context: "floquet".into(),
                expected: format!("a solution with {n} DOFs"),
                got: format!("{} DOFs", solution.dof_names().len()),
            });
        }
        match self.method.resolve(model) {
            FloquetMethod::Reduced => self.reduced(model, solution),
            _ => {
                // The monodromy matrix is dense (2n × 2n): refuse what would not fit.
                model.dense("stability (Floquet multipliers, dense method)")?;
                shoot(&Coordinates::full(model), solution, self)
            }
        }
    }

    /// On the reduced basis with the cut-off `cutoff · H Ω/ν`, and the estimate.
    fn reduced(&self, model: &Model, solution: &Solution) -> Result<Floquet> {
        let n = model.n_dofs();
        let top = solution.basis().harmonics() as f64 * solution.basis().fundamental();
        let cutoff = self.cutoff * top;
        let basis = reduced_basis(model, cutoff)?;
        let mut info = Reduction {
            dofs: basis.v.ncols(),
            modes: basis.modes,
            attachment: basis.attachment,
            cutoff,
            estimate: None,
            comparison_dofs: None,
        };
        let mut floquet = shoot(&Coordinates::reduced(model, basis.v), solution, self)?;
        if info.dofs >= n {
            info.estimate = Some(0.0);
        } else if self.estimate {
            // Twice the cut-off, doubled again (up to 2⁸ times) while that adds no vector.
            let mut wider = 2.0 * cutoff;
            let mut larger = reduced_basis(model, wider)?;
            for _ in 0..7 {
                if larger.v.ncols() > info.dofs {
                    break;
                }
                wider *= 2.0;
                larger = reduced_basis(model, wider)?;
            }
            info.comparison_dofs = Some(larger.v.ncols());
            let reference = shoot(&Coordinates::reduced(model, larger.v), solution, self)?;
            info.estimate = Some(distance(&floquet.multipliers, &reference.multipliers));
            floquet.steps += reference.steps;
        }
        floquet.reduction = Some(info);
        Ok(floquet)
    }
}

/// The larger of `max_i min_j |a_i - b_j|` over the leading `a_i` and the same over the
/// leading `b_j`, leading meaning a modulus at least half the largest of both sets (at most 8
/// from each): a multiplier that only one basis has counts with its distance to the other's
/// nearest.
fn distance(a: &[Complex64], b: &[Complex64]) -> f64 {
    let top = a
        .first()
        .map_or(0.0, |m| m.norm())
        .max(b.first().map_or(0.0, |m| m.norm()));
    let one_way = |a: &[Complex64], b: &[Complex64]| {
        a.iter()
            .take(8)
            .filter(|m| m.norm() >= 0.5 * top)
            .map(|m| b.iter().map(|o| (m - o).norm()).fold(m.norm(), f64::min))
            .fold(0.0, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}
