//! The AFT's quadrature error across contact edges where it is not exact.
//!
//! A law affine between its kinks and time jumps (`gap_contact`, `backlash` with a constant or
//! rectangular stiffness, `stop_spring`) has its harmonics integrated exactly across contact
//! edges ([`crate::harmonic::kinks::exact`]). Other laws with kinks (a cosine, Fourier or
//! sampled mesh stiffness under backlash, a user's law) take the trapezoid rule on the `N`
//! samples with the Euler–Maclaurin correction of the crossings, which leaves the jumps of
//! the third and higher derivatives: measured 3e-8 to 8e-8 of the load on the backlash pair
//! with a cosine stiffness. That error is measured at the solution, with the same harmonics
//! `Q` and eight times the samples:
//!
//! `ε_q = ‖F_rest^{8N}(Q) − F_rest^{N}(Q)‖ / ‖F_ext‖`
//!
//! (Parseval norms over the harmonics `0..=H`; without a load, relative to `‖F_rest^N(Q)‖`).
//! It is the residual the solution leaves in the Galerkin equations integrated exactly, up to
//! the finer rule's own error (a sixty-fourth or less of it), and what the solve's reported
//! residual cannot show, since the solver drives the `N`-sample residual to zero.

use crate::error::Result;
use crate::force::affine::affine_law;
use crate::model::Model;
use crate::residual::HarmonicBalance;
use crate::solution::Solution;
use num_complex::Complex64;

/// The reference's samples as a multiple of the solution's.
pub const QUADRATURE_OVERSAMPLING: usize = 8;

/// The measured quadrature error of a solution ([`quadrature_error`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct QuadratureError {
    /// `ε_q`, relative to the load (module documentation).
    pub relative: f64,
    /// The samples per period of the solution, `N`.
    pub samples: usize,
    /// The samples of the reference evaluation, [`QUADRATURE_OVERSAMPLING`]` · N`.
    pub reference_samples: usize,
}

/// The quadrature error of `solution` (module documentation), or `None` where every contact
/// crossing of its orbit is integrated exactly or none is crossed (nothing is evaluated where
/// no law could take the corrected trapezoid rule).
///
/// ```
/// use hbal::force::{Backlash, MeshProfile};
/// use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
/// // A contact with a cosine stiffness, pressed into contact and out of it once a period.
/// let law = Backlash::new(0.1, MeshProfile::Cosine { mean: 10.0, amplitude: 3.0 });
/// let model = Model::builder(&["x"])
///     .mass_diagonal(&[1.0])
///     .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.05))
///     .stiffness(hbal::nalgebra::DMatrix::from_element(1, 1, 1.0))
///     .element("contact", &[("x", 1.0)], law)
///     .load("x", 0, 0.3, 0.0)
///     .load("x", 1, 0.5, 0.0)
///     .build()?;
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.3, 16)?)?;
/// let solution = Newton::new().solve(&hb, &mut hb.workspace())?;
/// let e = hbal::solve::quadrature_error(&model, &solution)?.expect("contact crossed");
/// assert!(e.relative > 1e-14 && e.relative < 1e-4, "{}", e.relative);
/// # Ok::<(), hbal::Error>(())
/// ```
pub fn quadrature_error(model: &Model, solution: &Solution) -> Result<Option<QuadratureError>> {
    let basis = *solution.basis();
    let few = basis.samples() < 4 * basis.harmonics() + 1;
    let approximate = model.elements().iter().any(|e| {
        let law = e.law();
        let kinks = law.kinks();
        let reach = kinks.iter().fold(1.0_f64, |m, k| m.max(4.0 * k.abs()));
        !kinks.is_empty() && law.memory().is_none() && (few || !affine_law(law, reach, 1.0))
    });
    // A law with memory is marched through the samples: its own N-dependence would count
    // as contact quadrature (not measured there).
    if !approximate || basis.harmonics() == 0 || model.memory_element().is_some() {
        return Ok(None);
    }
    let n = model.n_dofs();
    let q = &solution.harmonics()[..(basis.harmonics() + 1) * n];
    let coarse = HarmonicBalance::new(model, basis)?;
    let mut ws = coarse.workspace();
    let mut rest = vec![Complex64::default(); q.len()];
    coarse.aft_into(q, &mut rest, None, &mut ws.eval)?;
    if ws.eval.approximate_contacts == 0 {
        return Ok(None);
    }
    let reference_samples = QUADRATURE_OVERSAMPLING * basis.samples();
    let fine = HarmonicBalance::new(model, basis.with_samples(reference_samples)?)?;
    let mut fine_ws = fine.workspace();
    let mut fine_rest = vec![Complex64::default(); q.len()];
    fine.aft_into(q, &mut fine_rest, None, &mut fine_ws.eval)?;
    let difference: Vec<Complex64> = fine_rest.iter().zip(&rest).map(|(a, b)| a - b).collect();
    let load = coarse.norm(coarse.external_load());
    let scale = if load > 0.0 { load } else { coarse.norm(&rest) };
    let d = coarse.norm(&difference);
    Ok(Some(QuadratureError {
        relative: if scale > 0.0 { d / scale } else { d },
        samples: basis.samples(),
        reference_samples,
    }))
}
