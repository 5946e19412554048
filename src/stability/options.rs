//! The options of a Floquet analysis: tolerance, method, basis, integrator and orbit.

use crate::model::Model;

/// Options of the Floquet analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloquetOptions {
    /// Relative tolerance of the Runge–Kutta integrator, and of the shooting (converged at a
    /// scaled residual of `10 rtol`). Default 1e-8 (multipliers to about 1e-7 or better; the
    /// exponential flow itself is exact up to rounding and the located crossings).
    pub rtol: f64,
    /// Newton shooting iterations (0: the multipliers along the orbit started from the HB
    /// state; a chord step that gains less than a factor 4 is not counted). Default 6.
    pub max_shooting: usize,
    /// Steps per period before giving up. Default 2 000 000.
    pub max_steps: usize,
    /// Dense monodromy matrix in the model's DOFs or on a reduced basis. Default
    /// [`FloquetMethod::Auto`].
    pub method: FloquetMethod,
    /// Cut-off of the reduced basis as a multiple of the highest frequency of the HB solution,
    /// `ω_c = cutoff · H Ω/ν`: every undamped mode below it is kept. `f64::INFINITY` keeps
    /// every mode (dense eigenproblem, up to 4096 DOFs). Default 3.
    pub cutoff: f64,
    /// Estimate the reduction's error by a second analysis on the basis with twice the cut-off
    /// ([`Reduction::estimate`](crate::stability::Reduction::estimate)); costs that analysis. Default `true`.
    pub estimate: bool,
    /// How the flow over a period is integrated. Default [`Integrator::Auto`].
    pub integrator: Integrator,
    /// Which orbit the monodromy matrix follows. Default [`Orbit::Exact`].
    pub orbit: Orbit,
}

/// The orbit whose monodromy matrix gives the multipliers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Orbit {
    /// The exact periodic orbit next to the HB solution, found by shooting: the orbit is
    /// integrated (sub-steps of the fastest motion, every kink crossing located) and
    /// corrected by Newton ([`Floquet::polished`](crate::stability::Floquet::polished)).
    #[default]
    Exact,
    /// The HB orbit itself, where the exponential flow applies: its kink crossings are the
    /// roots of the harmonics' element coordinates, and `Φ` is the product of the pieces'
    /// exponentials between them; no orbit is integrated, nothing is polished. The
    /// multipliers are those of the linearisation along the HB solution, as in Hill's method,
    /// accurate to about the HB solution's own error: [`Floquet::orbit_difference`](crate::stability::Floquet::orbit_difference) says how
    /// far from the exact orbit's on the same coordinates, as measured ([`Floquet::orbit_correction`](crate::stability::Floquet::orbit_correction)
    /// is 0: no shooting moved the orbit). Other laws, and [`Integrator::RungeKutta`], fall
    /// back on [`Orbit::Exact`].
    Harmonic,
}

/// The integrator of the orbit and its monodromy matrix over a period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Exact exponentials of the piecewise constant linearisation where every law is affine
    /// between its time jumps and kinks (rectangular or constant mesh stiffness, backlash,
    /// linear springs), Dormand–Prince otherwise.
    #[default]
    Auto,
    /// Dormand–Prince 5(4) with error control (`rtol`) for every model.
    RungeKutta,
}

impl Default for FloquetOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            max_shooting: 6,
            max_steps: 2_000_000,
            method: FloquetMethod::Auto,
            cutoff: 3.0,
            estimate: true,
            integrator: Integrator::Auto,
            orbit: Orbit::Exact,
        }
    }
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
}

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
    /// The leading multipliers of the HB orbit (largest moduli) by the Arnoldi iteration on
    /// the monodromy action, integrated in the model's own sparse matrices: no `2n × 2n`
    /// matrix, for models with many modes in the excitation band (`krylov_floquet` module).
    /// Diagonal mass matrices, no laws with memory, no free-free models.
    Arnoldi,
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
