//! The method choice: which multipliers a Floquet analysis computes and reports.
//!
//! [`dispatch`] picks the method ([`FloquetOptions::compute_with`](crate::stability::FloquetOptions::compute_with));
//! [`orbit_check`] runs the HB orbit's own multipliers and measures them against the exact
//! orbit's now and then; [`orbit_identity`] decides whose multipliers to report when the
//! shooting found another orbit than the HB solution's; [`cache`] is what a sweep's analyses
//! carry from point to point. Uses every other room; nothing uses it but the module root.

pub(crate) mod cache;
pub(crate) mod dispatch;
pub(crate) mod orbit_check;
pub(crate) mod orbit_identity;
