//! Force elements behind one trait.
//!
//! A force element acts on a scalar local coordinate `u = w·q` (see
//! [`Element`](crate::Element)) and returns the restoring force `f(θ, u, u̇)`, where
//! `θ = Ω t` is the angle of the fundamental (the law is 2π-periodic in θ). The element's force
//! on the model is `-w f`, so that a linear spring `f = k u` adds `k w wᵀ` to the stiffness.
//!
//! For the paper's split `K(t) = K0 + K1(t)`, `D(t) = D0 + D1(t)` every law names its constant
//! linear part `(k0, d0)` ([`ForceLaw::linear_part`]); the harmonic-balance iteration keeps
//! `k0 w wᵀ` in `K0` and evaluates only the rest `f - k0 u - d0 u̇` in the time domain.
//!
//! Built-in laws (scene-file names in brackets): [`LinearSpring`] (`linear_spring`),
//! [`MeshStiffness`] (`mesh_stiffness`), [`Backlash`] (`backlash`), [`CubicSpring`]
//! (`cubic_spring`), [`GapContact`] (`gap_contact`), [`StopSpring`] (`stop_spring`),
//! [`Friction`] (`friction`), [`QuadraticDamper`] (`quadratic_damper`),
//! [`PolynomialSpring`] (`polynomial_spring`), and with memory [`Jenkins`] (`jenkins`, see
//! [`memory`]). Any law acts on a shifted coordinate
//! `u - u0` through [`Offset`] (the element field `offset` in a scene file). Implement
//! [`ForceLaw`] in your own crate for anything else and check its derivatives with
//! [`check_derivatives`].

pub(crate) mod affine;
mod backlash;
mod check;
mod cubic_spring;
mod friction;
mod gap_contact;
mod jenkins;
mod linear_spring;
pub mod memory;
mod mesh_stiffness;
mod offset;
mod polynomial_spring;
mod profile;
mod quadratic_damper;
mod sampled;
mod stop_spring;

pub use backlash::{Backlash, Flank};
pub use check::{check_derivatives, DerivativeCheck};
pub use cubic_spring::CubicSpring;
pub use friction::Friction;
pub use gap_contact::{ContactState, GapContact};
pub use jenkins::Jenkins;
pub use linear_spring::LinearSpring;
pub use memory::{Hysteresis, StepDerivatives, MAX_STATE};
pub use mesh_stiffness::MeshStiffness;
pub use offset::Offset;
pub use polynomial_spring::PolynomialSpring;
pub(crate) use profile::check_teeth;
pub use profile::{MeshDamping, MeshProfile, MAX_TEETH};
pub use quadratic_damper::QuadraticDamper;
pub use stop_spring::{Stage, StopSpring};

use crate::Result;
use std::f64::consts::TAU;

/// The constant linear part `f ≈ f0 + k0 u + d0 u̇` of a force law: `k0`, `d0` go into `K0`,
/// `D0`; the offset `f0` is a static force of the linearisation (a contact engaged at
/// `u = b` has `f ≈ k (u - b)`, so `f0 = -k b`).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct LinearPart {
    /// Stiffness `k0 = ∂f/∂u`, averaged.
    pub stiffness: f64,
    /// Damping `d0 = ∂f/∂u̇`, averaged.
    pub damping: f64,
    /// Static offset `f0`; default 0.
    #[serde(default)]
    pub offset: f64,
}

/// A scalar force law `f(θ, u, u̇)` of one element.
///
/// `θ = Ω t` is the angle of the fundamental; the law must be 2π-periodic in θ. Implementations
/// must be `Send + Sync` and serialisable (`#[typetag::serde(name = "...")]` gives the scene-file
/// name).
///
/// # Example: a user law
/// ```
/// use hbal::force::ForceLaw;
///
/// /// A cubic damper `f = c u̇³`.
/// #[derive(Debug, serde::Serialize, serde::Deserialize)]
/// struct CubicDamper { c: f64 }
///
/// #[typetag::serde(name = "cubic_damper")]
/// impl ForceLaw for CubicDamper {
///     fn force(&self, _theta: f64, _u: f64, du: f64) -> f64 { self.c * du * du * du }
///     fn derivatives(&self, _theta: f64, _u: f64, du: f64) -> (f64, f64) {
///         (0.0, 3.0 * self.c * du * du)
///     }
/// }
/// let law = CubicDamper { c: 2.0 };
/// assert_eq!(law.force(0.0, 0.0, -3.0), -54.0);
/// let check = hbal::force::check_derivatives(&law, &[(0.3, 0.1, 0.7)]);
/// assert!(check.max_relative_error < 1e-6);
/// ```
#[typetag::serde(tag = "type")]
pub trait ForceLaw: std::fmt::Debug + Send + Sync {
    /// The restoring force `f(θ, u, u̇)`.
    fn force(&self, theta: f64, u: f64, du: f64) -> f64;

    /// The force at many samples: `out[j] = f(θ[j], u[j], u̇[j])`. All slices have one length.
    ///
    /// The AFT calls this once per element and pass; the default loops over
    /// [`ForceLaw::force`]. Override it where a law can hoist work out of the loop.
    fn force_batch(&self, theta: &[f64], u: &[f64], du: &[f64], out: &mut [f64]) {
        for (((o, &t), &x), &v) in out.iter_mut().zip(theta).zip(u).zip(du) {
            *o = self.force(t, x, v);
        }
    }

    /// The derivatives at many samples: `(dfdu[j], dfddu[j]) = derivatives(θ[j], u[j], u̇[j])`.
    /// The default loops over [`ForceLaw::derivatives`].
    fn derivatives_batch(
        &self,
        theta: &[f64],
        u: &[f64],
        du: &[f64],
        dfdu: &mut [f64],
        dfddu: &mut [f64],
    ) {
        for j in 0..theta.len() {
            (dfdu[j], dfddu[j]) = self.derivatives(theta[j], u[j], du[j]);
        }
    }

    /// The partial derivatives `(∂f/∂u, ∂f/∂u̇)` at `(θ, u, u̇)`, for Newton-type solvers.
    ///
    /// Where the law has a kink (contact), return either one-sided value.
    fn derivatives(&self, theta: f64, u: f64, du: f64) -> (f64, f64);

    /// The constant linear part `(k0, d0)` kept in `K0`, `D0`.
    ///
    /// Default: the time average of the linearisation at `u = u̇ = 0`,
    /// `k0 = (1/2π) ∫ ∂f/∂u(θ, 0, 0) dθ` (64-point rule), as in the paper's split
    /// `K(t) = K0 + K1(t)`. Override it where that average is a poor centre for the
    /// iteration (a contact that is open at `u = 0`).
    fn linear_part(&self) -> LinearPart {
        const POINTS: usize = 64;
        let (mut k, mut d) = (0.0, 0.0);
        for j in 0..POINTS {
            let (dk, dd) = self.derivatives(TAU * j as f64 / POINTS as f64, 0.0, 0.0);
            k += dk;
            d += dd;
        }
        LinearPart {
            stiffness: k / POINTS as f64,
            damping: d / POINTS as f64,
            offset: self.force_mean_at_rest(),
        }
    }

    /// The time average of `f(θ, 0, 0)` (64-point rule): the default offset of
    /// [`ForceLaw::linear_part`].
    fn force_mean_at_rest(&self) -> f64 {
        const POINTS: usize = 64;
        (0..POINTS)
            .map(|j| self.force(TAU * j as f64 / POINTS as f64, 0.0, 0.0))
            .sum::<f64>()
            / POINTS as f64
    }

    /// Angles `θ ∈ [0, 2π)` where the force jumps in time (a rectangular mesh stiffness).
    ///
    /// The time-domain reference restarts its integrator there; the AFT samples a jump with the
    /// mean of both one-sided limits, the value a Fourier series converges to. Default: none.
    fn time_breakpoints(&self) -> Vec<f64> {
        Vec::new()
    }

    /// The order (per revolution of θ) at which the law varies in time, if it does: the mesh
    /// cycles per period of a mesh stiffness. A harmonic basis with fewer harmonics cannot
    /// represent the variation and is refused ([`crate::HarmonicBalance::new`]). Default: none.
    fn time_order(&self) -> Option<usize> {
        None
    }

    /// A copy of this law for a harmonic basis with `samples` time samples per revolution of
    /// the shaft angle θ, whose time-varying coefficients keep only their Fourier orders in θ
    /// up to `max_order` and are tabulated at the sample angles `2π i / samples`; `None` (the
    /// default) where the law is sampled exactly as it is.
    ///
    /// The AFT evaluates this copy. A stiffness that jumps between samples otherwise costs
    /// O(1/N) in every harmonic; band-limited to `2H` orders (with `N >= 4H + 1`), the AFT of
    /// `k(θ) u` is the exact Galerkin projection of the product onto the kept harmonics. The
    /// time-domain reference and the Floquet analysis keep the law itself.
    fn band_limited(&self, samples: usize, max_order: usize) -> Option<Box<dyn ForceLaw>> {
        let _ = (samples, max_order);
        None
    }

    /// Values of `u` where the law is not smooth (a contact edge): its derivatives, and
    /// possibly the force itself (contact damping), jump when `u` crosses one of them.
    ///
    /// The Floquet analysis ([`crate::stability`]) locates every crossing of the orbit, restarts
    /// its integrator there and applies the saltation matrix of a force jump; a law that
    /// declares no kinks is treated as smooth. Default: none.
    fn kinks(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Names of the states between the law's [`kinks`](ForceLaw::kinks), from the lowest `u`
    /// up (a backlash contact: `coast`, `open`, `drive`), for reports of the fraction of the
    /// period spent in each. Default: none (reports number the intervals instead).
    fn state_names(&self) -> &'static [&'static str] {
        &[]
    }

    /// The memory of a hysteretic law (a friction slider), `None` (the default) for a law
    /// whose force depends only on `(θ, u, u̇)`.
    ///
    /// With memory, the AFT marches the samples of a period through
    /// [`Hysteresis::step`] until the loop closes and chains its derivatives for the Jacobian;
    /// the time-domain reference commits the state after every step; the Floquet analysis
    /// refuses the model. [`ForceLaw::force`] and [`ForceLaw::derivatives`] are then only the
    /// first step from the initial state. See [`memory`].
    fn memory(&self) -> Option<&dyn Hysteresis> {
        None
    }

    /// `true` if the force is exactly `k0 u + d0 u̇` at all times: the element then lives
    /// entirely in `K0`, `D0` and costs nothing in the time domain. Default: `false`.
    fn is_linear_time_invariant(&self) -> bool {
        false
    }

    /// `true` if the force is exactly `k(θ) u + d(θ) u̇` (linear in the state, no offset, the
    /// coefficients possibly varying in time, as a mesh stiffness): where its coefficients
    /// jump ([`ForceLaw::time_breakpoints`]), the harmonic balance corrects the coupling
    /// through the harmonics above H (see
    /// [`HarmonicBasis::with_tail_correction`](crate::HarmonicBasis::with_tail_correction)),
    /// on the copy [`ForceLaw::band_limited`] gives (a law without one is not corrected).
    /// Default: `false`.
    fn is_linear_in_state(&self) -> bool {
        false
    }

    /// `true` if the law is `k(θ) u + d(θ) u̇ + f_0(θ)` with `k`, `d` and the force at rest
    /// `f_0` constant between its [`time_breakpoints`](ForceLaw::time_breakpoints) (a
    /// rectangular mesh stiffness, also with an offset): a scene of such laws and linear ones
    /// is linear time-invariant piece by piece, and
    /// [`PiecewiseExact`](crate::solve::PiecewiseExact) solves it exactly. Default: `false`.
    fn is_piecewise_constant(&self) -> bool {
        false
    }

    /// Checks the parameters; `context` names the element in messages. Default: accepts.
    fn validate(&self, context: &str) -> Result<()> {
        let _ = context;
        Ok(())
    }
}
