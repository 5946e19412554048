//! The per-quantity error estimate as the CLI prints it: the worst DOF or element coordinate
//! and the worst element force, each by name and relative to its own range.

use hbal::solve::ErrorEstimate;
use hbal::Model;

/// `"; worst quantity u(mesh) 1.8e-2 of its range 4.1e-5, force f(mesh) 2.2e-2"`, or
/// nothing where the quantities were not estimated; with `"; contact quadrature 3.1e-8 of
/// the load (...)"` where a law's crossings take the corrected trapezoid rule.
pub(crate) fn summary(model: &Model, e: &ErrorEstimate) -> String {
    let mut out = String::new();
    if let Some(q) = e.worst_quantity {
        out += &format!(
            "; worst quantity {} {:.1e} of its range {:.3e}",
            q.quantity.name(model),
            q.error,
            q.range
        );
    }
    if let Some(f) = e.worst_force {
        out += &format!(", force {} {:.1e}", f.quantity.name(model), f.error);
    }
    if let Some(q) = e.quadrature {
        out += &format!(
            "; contact quadrature {:.1e} of the load (corrected trapezoid rule on {} samples, against {}: a law with kinks that is not affine between them)",
            q.relative, q.samples, q.reference_samples
        );
    }
    out
}
