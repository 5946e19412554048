//! What the torus balance evaluates: the time-varying and nonlinear elements on their bases
//! (their coordinates, band-limited laws and the grid points on their time jumps) and the
//! loads placed on the lines of their bases.

use super::{IndexSet, TorusModel};
use crate::error::{Error, Result};
use crate::force::{ForceLaw, LinearPart};
use num_complex::Complex64;
use std::f64::consts::TAU;
use std::sync::Arc;

/// A time-varying or nonlinear element on the torus.
#[derive(Debug, Clone)]
pub(super) struct TorusElement {
    pub(super) index: usize,
    pub(super) coordinate: usize,
    /// `w_e = s W[:, c]`.
    pub(super) factor: f64,
    pub(super) base: usize,
    /// The band-limited copy the AFT evaluates, where the law has one.
    pub(super) band_limited: Option<Arc<dyn ForceLaw>>,
    /// Grid points whose angle of the element's base sits on a time jump of the law.
    pub(super) jumps: Vec<usize>,
    /// The law's contact edges in u ([`ForceLaw::kinks`]), corrected along the base's lines.
    pub(super) kinks: Vec<f64>,
    pub(super) linear: LinearPart,
}

/// `F_j` of the loads on their bases, minus `Σ w f0` at the static line.
pub(super) fn full_load(tm: &TorusModel, set: &IndexSet, omega: f64) -> Result<Vec<Complex64>> {
    let model = tm.model();
    let (n, d) = (model.n_dofs(), set.dims());
    let mut f = vec![Complex64::default(); set.len() * n];
    for (l, load) in model.loads().iter().enumerate() {
        let b = tm.load_base(l);
        let mut k = vec![0i32; d];
        k[b] = i32::try_from(load.order).unwrap_or(i32::MAX);
        let Some(j) = set.position(&k) else {
            return Err(Error::InvalidElement {
                context: format!(
                    "load on `{}` order {} on base `{}`",
                    model.dof_names()[load.dof],
                    load.order,
                    tm.bases().names()[b]
                ),
                reason: format!(
                    "the torus keeps only {} harmonics of that base: raise its cap",
                    set.caps()[b]
                ),
            });
        };
        let (c, s) = load.at(omega);
        f[j * n + load.dof] += crate::harmonic::from_cos_sin(c, s);
    }
    for e in model.elements() {
        e.scatter_add(Complex64::new(-e.linear_part().offset, 0.0), &mut f[..n]);
    }
    Ok(f)
}

/// The time-varying or nonlinear elements, their coordinates (parallel weights merged) and
/// the coordinates' names.
#[allow(clippy::type_complexity)]
pub(super) fn active_elements(
    tm: &TorusModel,
    set: &IndexSet,
    dims: &[usize],
) -> Result<(Vec<TorusElement>, Vec<Vec<(usize, f64)>>, Vec<String>)> {
    let model = tm.model();
    let mut coordinates: Vec<Vec<(usize, f64)>> = Vec::new();
    let mut names = Vec::new();
    let mut active = Vec::new();
    for (index, e) in model.elements().iter().enumerate() {
        if e.law().is_linear_time_invariant() {
            continue;
        }
        let base = tm.element_base(index);
        let (cap, nb) = (set.caps()[base], dims[base]);
        let context = format!(
            "element `{}` on torus base `{}`",
            e.name(),
            tm.bases().names()[base]
        );
        if e.law().memory().is_some() {
            return Err(Error::InvalidElement {
                context,
                reason: "a law with memory (a friction slider) is not available on the torus yet; use the one-frequency basis".into(),
            });
        }
        if let Some(order) = e.law().time_order() {
            let mut k = vec![0i32; set.dims()];
            k[base] = i32::try_from(order).unwrap_or(i32::MAX);
            if !set.contains_either_sign(&k) {
                return Err(Error::InvalidElement {
                    context,
                    reason: format!(
                        "the law varies at order {order} of its base but the index set does not hold that line (caps {:?}, {:?}): raise the cap or the total degree, or bind it to a base that turns {order} times faster",
                        set.caps(),
                        set.truncation()
                    ),
                });
            }
        }
        let found = coordinates.iter().enumerate().find_map(|(c, v)| {
            crate::linear::condensation::parallel(e.weights(), v).map(|s| (c, s))
        });
        let (coordinate, factor) = found.unwrap_or_else(|| {
            coordinates.push(e.weights().to_vec());
            names.push(format!("u({})", e.name()));
            (coordinates.len() - 1, 1.0)
        });
        let band = if nb > 4 * cap {
            2 * cap
        } else {
            nb.saturating_sub(2 * cap + 1).max(cap / 2)
        };
        let band_limited: Option<Arc<dyn ForceLaw>> =
            e.law().band_limited(nb, band).map(Into::into);
        let law = band_limited.as_deref().unwrap_or(e.law());
        let on_jump: Vec<bool> = {
            let mut marks = vec![false; nb];
            for b in law.time_breakpoints() {
                let x = b.rem_euclid(TAU) / TAU * nb as f64;
                if (x - x.round()).abs() < 1e-9 {
                    marks[x.round() as usize % nb] = true;
                }
            }
            marks
        };
        let stride: usize = dims[base + 1..].iter().product();
        let points: usize = dims.iter().product();
        let jumps = if on_jump.iter().any(|&j| j) {
            (0..points).filter(|p| on_jump[(p / stride) % nb]).collect()
        } else {
            Vec::new()
        };
        let kinks = law.kinks().into_iter().filter(|k| k.is_finite()).collect();
        active.push(TorusElement {
            index,
            coordinate,
            factor,
            base,
            band_limited,
            jumps,
            kinks,
            linear: e.linear_part(),
        });
    }
    Ok((active, coordinates, names))
}
