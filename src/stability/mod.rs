//! Stability of a periodic solution: Floquet multipliers from the monodromy matrix.
//!
//! The variational equation of `M q̈ + D q̇ + K q + Σ w f(θ, w·q, w·q̇) = f(t)` about a periodic
//! solution `q*(t)` is `ż = A(t) z`, `z = (δq, δq̇)`, with
//!
//! `A(t) = [[0, I], [-M⁻¹ (K + Σ w k(t) wᵀ), -M⁻¹ (D + Σ w d(t) wᵀ)]]`,
//! `k(t) = ∂f/∂u`, `d(t) = ∂f/∂u̇` at `(Ω t, w·q*, w·q̇*)`.
//!
//! The monodromy matrix `Φ(T)` solves `Φ̇ = A(t) Φ`, `Φ(0) = I`, over one period; its
//! eigenvalues are the Floquet multipliers. hbal integrates it together with the orbit itself,
//! restarted at every time jump of a law and at every kink crossing, with the saltation matrix
//! where a force jumps ([`Integrator`]):
//!
//! * where every law is affine between its time jumps and kinks (rectangular or constant mesh
//!   stiffness, backlash and stop contacts, linear springs and dampers), `A` is constant on
//!   each piece and the flow is exact: `Φ` is multiplied by `e^{A h}` per piece, the orbit
//!   marched by exact sub-steps with the load as an oscillator (`exponential/`), the
//!   stiffness of contact modes costs nothing;
//! * otherwise by Dormand–Prince 5(4) with error control, the step limited by the fastest time
//!   scale of the model along the orbit (`integrated/`).
//!
//! It starts on the harmonic-balance orbit and polishes it by Newton shooting,
//! `x₀ ← x₀ - (Φ - I)⁻¹ (φ_T(x₀) - x₀)`, so the multipliers belong to the exact periodic orbit
//! next to the HB solution, to the integrator's tolerance, whatever H; the size of that
//! correction ([`Floquet::orbit_correction`]) measures the HB solution's own error at `t = 0`.
//! A sweep's points share a [`FloquetCache`] (the modes of a reduced basis, the last orbit
//! corrections, extrapolated to the next shooting's start, and the last `Φ` as the Jacobian
//! of its chord steps). The exponential flow integrates the orbit alone and forms `Φ` only for
//! the orbits that need it, the converged one at least, from the record of its pieces: with
//! two cores on a second thread while the orbit is integrated (the same `Φ` to the last bit).
//!
//! Rigid-body modes give multipliers that are exactly 1 by construction; they are identified
//! from the model ([`Floquet::neutral`]) and left out of [`Floquet::multipliers`] and the
//! stability decision. The solution is stable if every other multiplier lies inside the unit
//! circle (up to [`STABILITY_MARGIN`]). A multiplier leaving through +1 is a fold (or a
//! symmetry-breaking branch point), through −1 a period doubling, a complex pair a
//! Neimark–Sacker bifurcation.
//!
//! **Large models.** The dense `Φ` costs `O(n³)` per step. From
//! [`FloquetMethod::REDUCED_FROM`] DOFs on (or with [`FloquetMethod::Reduced`]) the same
//! shooting runs on the Galerkin projection onto `V` = the undamped modes of `(K0, M)` below
//! `ω_c = cutoff · H Ω/ν` plus the static attachment modes of the element coordinates (sparse Cholesky of `K0 + σM`, shift-invert subspace iteration), with the
//! model's own force laws on `u_e = (Vᵀw_e)·p`; [`Floquet::reduction`] records the basis and
//! an accuracy estimate against the basis with twice the cut-off. With every mode kept the
//! projection is a similarity transform and gives the dense multipliers.
//!
//! ## Which method runs when
//!
//! [`FloquetOptions::compute_with`] (in `choice/`) decides, in this order:
//!
//! | model or option | method | room |
//! |---|---|---|
//! | a law with memory (hysteresis) | shooting on the time-domain model with the laws' states | `shooting/` (`memory_shooting`) |
//! | linear and time-invariant | closed form `μ = e^{λT}` from the state matrix's eigenvalues | `time_invariant` |
//! | [`FloquetMethod::Auto`], many DOFs, every mode in the band (or [`FloquetMethod::Arnoldi`]) | leading multipliers by Arnoldi on the monodromy action | `large/` (`krylov_floquet`) |
//! | from [`FloquetMethod::REDUCED_FROM`] DOFs (or [`FloquetMethod::Reduced`]) | the shooting below on the reduced basis, with its estimate | `large/` (`reduction`) |
//! | [`Orbit::Exact`] (default) | Newton shooting onto the exact orbit | `shooting/` |
//! | [`Orbit::Harmonic`] | `Φ` along the HB orbit's own pieces, checked against the exact orbit now and then | `harmonic_orbit`, `choice/` (`orbit_check`) |
//!
//! The shooting integrates each period by the exact exponential product where every law is
//! piecewise affine (`exponential/`), by Runge–Kutta otherwise (`integrated/`). When it
//! lands on another orbit than the HB solution's, `choice/` (`orbit_identity`) reports the HB
//! orbit's own multipliers. The rigid-body modes are taken out by `neutral` in every method.
//!
//! ## Rooms and their data flow
//!
//! The shared ground, used by every room and using none: `multipliers` (the result),
//! `options`, `system` (the coordinates, full or reduced), `neutral`, `scales`,
//! `hb_state` (the HB state at `t = 0` and distances from it), `linear_rate` (a bound on
//! the fastest rate). The rooms, in the order of their use: `integrated/` (the shared ground
//! only); `exponential/` (uses `integrated/`'s pieces); `harmonic_orbit` (the exponential
//! flow along the HB orbit) and `shooting/` (both flows); `time_invariant` and `large/` (the
//! shared ground only); `choice/` (all of them). A test
//! (`tests/integration/stability_rooms.rs`) keeps it so: no import
//! circle between the files and folders of this module.
//!
//! ```
//! use hbal::force::CubicSpring;
//! use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
//! // A Duffing oscillator far from resonance: one stable orbit.
//! let model = Model::builder(&["x"])
//!     .mass_diagonal(&[1.0])
//!     .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.02))
//!     .element("spring", &[("x", 1.0)], CubicSpring::new(1.0, 1.0))
//!     .load("x", 1, 0.1, 0.0)
//!     .build()?;
//! let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.5, 7)?)?;
//! let solution = Newton::new().solve(&hb, &mut hb.workspace())?;
//! let floquet = hbal::stability::floquet(&model, &solution)?;
//! assert!(floquet.is_stable());
//! // The product of the multipliers is det Φ = exp(-c T / m) (Liouville):
//! let product: f64 = floquet.multipliers.iter().map(|m| m.norm()).product();
//! // (to the integrator's default tolerance, rtol 1e-8: here 1e-7)
//! assert!((product - (-0.02 * std::f64::consts::TAU / 0.5_f64).exp()).abs() < 1e-6);
//! # Ok::<(), hbal::Error>(())
//! ```

mod choice;
mod exponential;
mod harmonic_orbit;
mod hb_state;
mod integrated;
mod large;
mod linear_rate;
mod multipliers;
mod neutral;
mod options;
mod scales;
mod shooting;
mod system;
mod time_invariant;

pub use choice::cache::FloquetCache;
pub(crate) use exponential::expm;
pub use hb_state::{orbit_distance, OTHER_ORBIT_DISTANCE};
pub(crate) use large::modes::lowest_modes;
pub(crate) use linear_rate::fastest_rate;
pub(crate) use multipliers::{distance, eigenvalues};
pub use multipliers::{Bifurcation, Floquet, Reduction, ORBIT_CHECK_EVERY, STABILITY_MARGIN};
pub use options::{FloquetMethod, FloquetOptions, Integrator, Orbit};
pub use shooting::memory_shooting::{
    available as memory_stability_available, MAX_DOFS as MAX_MEMORY_DOFS,
};
pub(crate) use time_invariant::eigenvalues as state_eigenvalues;

use crate::error::Result;
use crate::model::Model;
use crate::solution::Solution;

/// Why no Floquet multipliers are computed for `model`, if they are not: laws with memory in
/// a free-free model or above [`MAX_MEMORY_DOFS`]; hysteretic damping, which has no
/// time-domain form (and so no variational equation).
pub fn unavailable(model: &Model) -> Option<String> {
    if model.has_hysteretic_damping() {
        return Some("not available with hysteretic damping (a loss factor, c = H/ω): it has no time-domain form".into());
    }
    let element = model
        .memory_element()
        .filter(|_| !memory_stability_available(model))?;
    Some(format!(
        "not available for laws with memory (element `{}`) in a free-free model or above {} DOFs",
        element.name(),
        MAX_MEMORY_DOFS
    ))
}

/// Floquet multipliers of `solution` (a periodic solution of `model`) with the default
/// [`FloquetOptions`].
pub fn floquet(model: &Model, solution: &Solution) -> Result<Floquet> {
    FloquetOptions::default().compute(model, solution)
}
