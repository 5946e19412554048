//! The exact exponential product: where every law is affine between its time jumps and kinks
//! (rectangular or constant mesh stiffness, backlash and stop contacts, linear springs and
//! dampers), `A(t)` is constant on each piece and `Φ` is the product of `e^{A h}` over the
//! pieces, exact up to rounding and the located crossings.
//!
//! Data flow: [`exp_flow`] marches the orbit by exact sub-steps (the load as an oscillator,
//! [`affine`]), [`kinks`] locates the crossings between pieces, [`generator`] and [`expm`]
//! form the pieces' exponentials (with [`kernels`], the small dense products, and
//! [`propagator`], a piece's propagator over a sub-step), [`kept`] keeps them from one point
//! of a sweep to the next, [`record`] records the pieces of a period and assembles `Φ` from
//! them, on a second thread while the orbit is integrated ([`pipeline`]).
//! [`integration`] puts this flow and the integrated one ([`crate::stability::integrated`])
//! behind one interface for the shooting. Uses the integrated flow's piece bookkeeping; used
//! by the shooting and the HB-orbit method.

pub(crate) mod affine;
pub(crate) mod exp_flow;
pub(crate) mod expm;
pub(crate) mod generator;
pub(crate) mod integration;
pub(crate) mod kept;
pub(crate) mod kernels;
pub(crate) mod kinks;
pub(crate) mod pipeline;
pub(crate) mod propagator;
pub(crate) mod record;
