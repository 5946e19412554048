//! Laws with memory (hysteresis): the force depends on the history of `u`, not only on the
//! present `(θ, u, u̇)`.
//!
//! A hysteretic law carries a small internal state `s` (a slider position, at most
//! [`MAX_STATE`] numbers) and advances it from one time sample to the next by a *step*, the
//! return mapping of plasticity:
//!
//! `(f_j, s_j) = step(s_{j-1}; θ_j, u_j, u̇_j)`.
//!
//! A law exposes it through [`ForceLaw::memory`](super::ForceLaw::memory). The AFT then marches
//! the N samples of a period from the law's initial state, pass after pass, until the state at
//! the start of a pass repeats (the hysteresis loop closes), and takes the forces of the last
//! pass; its Jacobian chains the step derivatives
//!
//! `∂f_j/∂x = f_u ∂u_j/∂x + f_u̇ ∂u̇_j/∂x + f_s ∂s_{j-1}/∂x`,
//! `∂s_j/∂x = s_u ∂u_j/∂x + s_u̇ ∂u̇_j/∂x + s_s ∂s_{j-1}/∂x`
//!
//! through every pass (see [`crate::harmonic::march`]). The time-domain reference
//! ([`crate::timesim`]) commits the step after every accepted integrator step.

/// Largest state of a hysteretic law (numbers per element).
pub const MAX_STATE: usize = 4;

/// The derivatives of one [`Hysteresis::step`]: of the force `f_j` and of the new state `s_j`
/// with respect to `u_j`, `u̇_j` and the previous state `s_{j-1}`. Entries beyond the law's
/// [`Hysteresis::state_len`] are ignored.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepDerivatives {
    /// `∂f_j/∂u_j`.
    pub df_du: f64,
    /// `∂f_j/∂u̇_j`.
    pub df_ddu: f64,
    /// `∂f_j/∂s_{j-1}`.
    pub df_ds: [f64; MAX_STATE],
    /// `∂s_j/∂u_j`.
    pub ds_du: [f64; MAX_STATE],
    /// `∂s_j/∂u̇_j`.
    pub ds_ddu: [f64; MAX_STATE],
    /// `∂(s_j)_r/∂(s_{j-1})_c` at `[r][c]`.
    pub ds_ds: [[f64; MAX_STATE]; MAX_STATE],
}

/// The memory of a hysteretic force law: a state and its step (module documentation).
///
/// A step must depend on the path only through the state: marching the same samples from the
/// same state gives the same forces (the AFT relies on it to detect the closed loop).
pub trait Hysteresis: std::fmt::Debug + Send + Sync {
    /// Numbers in the state, `1..=MAX_STATE`.
    fn state_len(&self) -> usize;

    /// Writes the initial (virgin) state into `state` (length [`Hysteresis::state_len`]):
    /// where the time-domain reference starts and where every AFT march starts.
    fn initial_state(&self, state: &mut [f64]);

    /// Advances `state` (from the previous sample) to the present sample `(θ, u, u̇)` and
    /// returns the force there.
    fn step(&self, theta: f64, u: f64, du: f64, state: &mut [f64]) -> f64;

    /// [`Hysteresis::step`] and its derivatives into `d`.
    fn step_derivatives(
        &self,
        theta: f64,
        u: f64,
        du: f64,
        state: &mut [f64],
        d: &mut StepDerivatives,
    ) -> f64;
}
