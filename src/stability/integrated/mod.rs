//! The integrated flow: the orbit and its monodromy matrix `Φ̇ = A(t) Φ` by Dormand–Prince
//! 5(4) with error control, for every law (the general method).
//!
//! [`flow`] advances the state and, where asked, `Φ` together ([`flow::Flow`]); [`dopri`] is
//! the Runge–Kutta stepper and its dense output; [`pieces`] locates the time jumps and kink
//! crossings where the flow restarts (with the saltation matrix where a force jumps), on the
//! cubic interpolant of [`cubic`]; [`guide`] bounds the step by the HB orbit's own
//! acceleration. Depends on nothing else in `stability` but the shared coordinates.

pub(crate) mod cubic;
pub(crate) mod dopri;
pub(crate) mod flow;
pub(crate) mod guide;
pub(crate) mod pieces;
