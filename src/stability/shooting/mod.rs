//! Newton shooting: polishes the HB state at `t = 0` onto the exact periodic orbit next to it,
//! `x₀ ← x₀ − (Φ − I)⁻¹ (φ_T(x₀) − x₀)`, so the multipliers belong to that orbit.
//!
//! [`shoot`] runs the iteration on either flow ([`crate::stability::exponential::integration`])
//! and returns the multipliers with the orbit correction; [`chord`] takes the cheaper chord
//! steps on a kept monodromy matrix; [`memory_shooting`] shoots the time-domain model with
//! the states of laws with memory (hysteresis), whose variational equation is not the one of
//! `(∂f/∂u, ∂f/∂u̇)`. Uses both flows; used by the method choice.

pub(crate) mod chord;
pub(crate) mod memory_shooting;
pub(crate) mod shoot;
