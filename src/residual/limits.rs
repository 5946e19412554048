//! The size of a harmonic-balance system, estimated and checked before anything is allocated.
//!
//! The memory of [`HarmonicBalance`](super::HarmonicBalance) grows with the DOFs `n`, the
//! harmonics `H` and the samples `N`:
//!
//! - harmonic vectors (loads, workspace): about `6 (H+1) n` complex numbers;
//! - time samples (angles, AFT buffers, a tabulated stiffness per time-varying element):
//!   about `(12 + m) N` reals with `m` nonlinear or time-varying elements;
//! - the factored dynamic stiffness `Z_k`, `k = 0..=H`: in the full formulation a dense
//!   `n × n` matrix and its LU per harmonic, `2 (H+1) n²` complex numbers; condensed, the
//!   `m × m` blocks `G_k⁻¹` and the sparse factors (at most 16 entries per nonzero of `M`,
//!   `D`, `K`), `(H+1) (2 m² + 16 (nnz + n))`.
//!
//! A system whose estimate exceeds [`MAX_SYSTEM_BYTES`] is refused with
//! [`Error::TooLarge`], which says what to lower; the allocation itself would abort the
//! process.

use crate::error::{Error, Result};
use crate::linear::Formulation;
use crate::{HarmonicBasis, Model};

/// Largest estimated memory of one harmonic-balance system: 4 GiB.
pub const MAX_SYSTEM_BYTES: f64 = 4.0 * GIB;

const GIB: f64 = (1u64 << 30) as f64;

/// Bytes of one complex number.
const COMPLEX: f64 = 16.0;

/// The estimated memory of the harmonic-balance system of `model` on `basis` in bytes (module
/// documentation).
pub fn estimate_bytes(model: &Model, basis: &HarmonicBasis, formulation: Formulation) -> f64 {
    let n = model.n_dofs() as f64;
    let h1 = (basis.harmonics() + 1) as f64;
    let active = model
        .elements()
        .iter()
        .filter(|e| !e.law().is_linear_time_invariant())
        .count() as f64;
    let vectors = 6.0 * h1 * n * COMPLEX;
    let time = (12.0 + active) * basis.samples() as f64 * 8.0;
    let linear = match formulation.resolve(model) {
        Formulation::Condensed => {
            let nnz = (model.mass().nnz()
                + model.structural_damping().nnz()
                + model.structural_stiffness().nnz()) as f64
                + n;
            h1 * (2.0 * active * active + 16.0 * nnz) * COMPLEX
        }
        _ => 2.0 * h1 * n * n * COMPLEX,
    };
    vectors + time + linear
}

/// Refuses a system above [`MAX_SYSTEM_BYTES`], naming its size and what to lower.
pub(crate) fn check_size(
    model: &Model,
    basis: &HarmonicBasis,
    formulation: Formulation,
) -> Result<()> {
    let bytes = estimate_bytes(model, basis, formulation);
    if bytes <= MAX_SYSTEM_BYTES {
        return Ok(());
    }
    let dense = formulation.resolve(model) != Formulation::Condensed;
    Err(Error::TooLarge {
        what: format!(
            "the harmonic-balance system ({} DOFs, H = {}, N = {}, {} formulation)",
            model.n_dofs(),
            basis.harmonics(),
            basis.samples(),
            if dense { "full" } else { "condensed" }
        ),
        size: format!("{:.1} GiB", bytes / GIB),
        limit: format!("{:.0} GiB", MAX_SYSTEM_BYTES / GIB),
        advice: if dense
            && model.n_dofs() > 1
            && model
                .elements()
                .iter()
                .any(|e| !e.law().is_linear_time_invariant())
        {
            "use fewer harmonics or samples, or the condensed formulation".into()
        } else {
            "use fewer harmonics or samples".into()
        },
    })
}
