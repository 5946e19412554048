//! Modal damping of a shaft line (`[line] modal_damping`): a damping matrix from damping
//! ratios of the undamped modes, as shaft-line tools build it.
//!
//! With `M = L Lᵀ` (Cholesky) and the eigen-decomposition `L⁻¹ K L⁻ᵀ = V Λ Vᵀ`, the
//! mass-normalised modes are `Φ = L⁻ᵀ V` (`Φᵀ M Φ = I`, `Φᵀ K Φ = Λ`, `ω_r = √λ_r`), and the
//! damping that gives mode r the ratio `ζ_r` is
//!
//! `D = M Φ diag(2 ζ_r ω_r) Φᵀ M = L V diag(2 ζ_r ω_r) Vᵀ Lᵀ`
//!
//! (`Φᵀ D Φ = diag(2 ζ_r ω_r)`). Rigid modes (`λ_r <= 1e-10 λ_max`) get none, so the line
//! still floats free where it did. `ζ` is one ratio for every mode, or one per elastic mode
//! in ascending frequency.

use nalgebra::{DMatrix, DVector};
use serde::Deserialize;

/// `modal_damping`: one ratio for every mode, or one per elastic mode.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub(super) enum ModalDamping {
    /// The same ratio for every elastic mode.
    All(f64),
    /// One ratio per elastic mode, lowest frequency first.
    PerMode(Vec<f64>),
}

/// The modal damping matrix of `mass`, `stiffness` (dense, symmetric); errors are
/// `(field path, message)`.
pub(super) fn damping(
    ratios: &ModalDamping,
    mass: &DMatrix<f64>,
    stiffness: &DMatrix<f64>,
) -> Result<DMatrix<f64>, (String, String)> {
    let field = "line.modal_damping";
    let list: Vec<f64> = match ratios {
        ModalDamping::All(z) => vec![*z],
        ModalDamping::PerMode(z) => z.clone(),
    };
    if let Some((i, z)) = list
        .iter()
        .enumerate()
        .find(|(_, z)| !(z.is_finite() && **z >= 0.0))
    {
        let at = match ratios {
            ModalDamping::All(_) => field.to_string(),
            ModalDamping::PerMode(_) => format!("{field}[{i}]"),
        };
        return Err((at, format!("must be finite and >= 0, got {z}")));
    }
    let l = mass
        .clone()
        .cholesky()
        .ok_or_else(|| {
            (
                field.to_string(),
                "needs a positive definite mass matrix".to_string(),
            )
        })?
        .l();
    let l_inv = l
        .clone()
        .try_inverse()
        .ok_or_else(|| (field.to_string(), "needs a regular mass matrix".to_string()))?;
    let a = &l_inv * stiffness * l_inv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eigen = a.symmetric_eigen();
    let mut order: Vec<usize> = (0..eigen.eigenvalues.len()).collect();
    order.sort_by(|&x, &y| eigen.eigenvalues[x].total_cmp(&eigen.eigenvalues[y]));
    let top = eigen.eigenvalues.iter().fold(0.0f64, |m, v| m.max(*v));
    let elastic: Vec<usize> = order
        .into_iter()
        .filter(|&r| eigen.eigenvalues[r] > 1e-10 * top)
        .collect();
    if let ModalDamping::PerMode(z) = ratios {
        if z.len() != elastic.len() {
            return Err((
                field.into(),
                format!(
                    "has {} ratios and the line has {} elastic modes (rigid ones get none): give one per elastic mode, lowest first, or one number for all",
                    z.len(),
                    elastic.len()
                ),
            ));
        }
    }
    let mut weights = DVector::zeros(eigen.eigenvalues.len());
    for (j, &r) in elastic.iter().enumerate() {
        let zeta = list[j.min(list.len() - 1)];
        weights[r] = 2.0 * zeta * eigen.eigenvalues[r].sqrt();
    }
    let v = &eigen.eigenvectors;
    let lv = &l * v;
    let d = &lv * DMatrix::from_diagonal(&weights) * lv.transpose();
    Ok((&d + d.transpose()) * 0.5)
}
