//! The reduced basis of the Floquet analysis at scale: the lowest undamped modes plus static
//! attachment modes (Craig–Bampton style residual flexibility), M-orthonormal.
//!
//! `V = [Φ_r  A]`, with `Φ_r` the modes of `K0 φ = ω² M φ` with `ω <= ω_c` (the cut-off) and
//! `A = (K0 + σM)⁻¹ [w_e …]` the static responses to a unit force on every time-varying or
//! nonlinear element coordinate `u_e = w_eᵀq`. The modes carry the dynamics up to `ω_c`; the
//! attachment modes make the element coordinates' static flexibility exact, so the contact
//! states and the mean wind-up of the reduced orbit are those of the full model, and the
//! truncated modes enter quasi-statically. Attachment vectors are M-orthogonalised against the
//! modes and each other (twice, Gram–Schmidt) and dropped when they lie in the span already
//! (relative M-norm below 1e-8): with every mode kept, `V` is square and invertible, and the
//! reduction a similarity transform.
//!
//! **No attachment modes for the loads.** The loads do not enter the variational equation,
//! and the orbit acts on it only through the element coordinates. Those see a static load `f`
//! exactly without a load attachment mode (Maxwell's reciprocity): the Galerkin solution
//! `q_r ∈ span V` of `K q = f` is `K`-orthogonal to the error, and `K⁻¹ w_e ∈ span V`, so
//! `w_eᵀ q_r = (K⁻¹w_e)ᵀ K q_r = (K⁻¹w_e)ᵀ f = w_eᵀ K⁻¹ f` (up to the shift σ). On the
//! drivetrain (8 loaded DOFs) leaving them out takes the basis from 17 to 13 coordinates and
//! the stability's work per point down by 30 %; the leading multipliers moved by at most
//! 4e-5, towards those on the basis with four times the cut-off. (A model with no element and
//! no mode below the cut-off keeps the loads' attachment modes, so that its basis is not
//! empty.)
//!
//! The modes come from a [`ModeCache`], computed once per model up to a reach (by default
//! twice the cut-off) and selected below each cut-off.
//!
//! The shift `σ = 10⁻⁴ ω_ref²` (`ω_ref` the first mode above the cut-off where the cache knows
//! it, else the cut-off, or for every mode the largest `sqrt(K0_ii / M_ii)`) makes a free-free
//! model's singular `K0` factorisable. It leaves the attachment modes' components along the
//! modes left out (weights `1/(ω_j² + σ)`, `ω_j > ω_c`) unchanged to 10⁻⁴; taken from the
//! modes, it is the same for every cut-off between two modes, and a sweep's points share the
//! basis until a mode crosses the cut-off.
//!
//! What it leaves out: the modes above `ω_c` as dynamic degrees of freedom, and so their
//! multipliers. With structural damping they lie deep inside the unit circle
//! (`|μ| = e^{-ζ ω T}`); an undamped model's would lie on it and are not reported.

use super::modes::{lowest_modes, ShiftedStiffness, DENSE_MODES};
use crate::error::{Error, Result};
use crate::model::{Model, SparseMatrix};
use nalgebra::{DMatrix, DVector};
use std::hash::{Hash, Hasher};

/// A reduced basis and what it holds.
#[derive(Debug, Clone)]
pub(crate) struct Basis {
    /// `V` (n × (r + a)), M-orthonormal.
    pub(crate) v: DMatrix<f64>,
    /// r, the modes kept.
    pub(crate) modes: usize,
    /// a, the attachment modes kept.
    pub(crate) attachment: usize,
    /// `(VᵀMV, VᵀDV, VᵀKV)` of the structure, formed once per basis (a sweep's points share
    /// it).
    pub(crate) projected: std::sync::Arc<(DMatrix<f64>, DMatrix<f64>, DMatrix<f64>)>,
}

/// The modes of `(K0, M)` computed so far for one model (identified by a hash of `K0` and
/// `M`): every mode with `ω² <= complete`. The modes do not depend on the speed, so a sweep
/// computes them once (up to twice the first point's cut-off, which also covers the
/// estimate's basis) and selects the ones below each point's cut-off.
#[derive(Debug, Clone, Default)]
pub(crate) struct ModeCache {
    fingerprint: u64,
    complete: f64,
    values: Vec<f64>,
    vectors: DMatrix<f64>,
    /// The last basis made from these modes, with a hash of what else it depends on (the
    /// modes kept, the shift, the unit forces of the elements). A sweep's cut-off
    /// moves with Ω, but the modes below it (and so the basis) change only where a mode
    /// crosses it.
    last: Option<(u64, Basis)>,
}

impl ModeCache {
    /// How many modes of `model` (`k0` its `K0`) have `ω <= cutoff` (the first that many of
    /// `vectors`) and `ω²` of the next one if known, computing every mode up to
    /// `reach >= cutoff` if they are not known yet.
    fn below(
        &mut self,
        model: &Model,
        k0: &SparseMatrix,
        cutoff: f64,
        reach: f64,
    ) -> Result<(usize, Option<f64>)> {
        let fingerprint = fingerprint(model.mass(), k0);
        if fingerprint != self.fingerprint || self.complete < cutoff * cutoff {
            let reach = reach.max(cutoff);
            let (modes, _) =
                lowest_modes(k0, model.mass(), reach * reach, shift(model, k0, reach))?;
            self.fingerprint = fingerprint;
            // The dense eigenproblem gives every mode.
            self.complete = if k0.n() <= DENSE_MODES {
                f64::INFINITY
            } else {
                reach * reach
            };
            self.values = modes.values;
            self.vectors = modes.vectors;
            self.last = None;
        }
        let r = self
            .values
            .iter()
            .filter(|&&v| v <= cutoff * cutoff)
            .count();
        Ok((r, self.values.get(r).copied()))
    }
}

/// A hash of the entries of `m` and `k0`.
fn fingerprint(m: &SparseMatrix, k0: &SparseMatrix) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for a in [m, k0] {
        a.n().hash(&mut h);
        for (i, j, v) in a.iter() {
            (i, j, v.to_bits()).hash(&mut h);
        }
    }
    h.finish()
}

/// The shift `σ = 10⁻⁴ ω_ref²` of the factorisation for the cut-off `cutoff`.
fn shift(model: &Model, k0: &SparseMatrix, cutoff: f64) -> f64 {
    let m = model.mass();
    let reference = if cutoff.is_finite() {
        cutoff
    } else {
        (0..k0.n())
            .map(|i| k0.get(i, i) / m.get(i, i))
            .fold(0.0, f64::max)
            .sqrt()
    };
    1e-4 * reference * reference
}

/// The basis of the modes with `ω <= cutoff` (rad/s; `f64::INFINITY` for all) and the
/// attachment modes of `model`, the modes from `cache` (computed up to `reach` if missing).
pub(crate) fn reduced_basis(
    model: &Model,
    cutoff: f64,
    reach: f64,
    cache: &mut ModeCache,
) -> Result<Basis> {
    let n = model.n_dofs();
    if cutoff.is_infinite() && n > DENSE_MODES.max(Model::MAX_DENSE_DOFS) {
        return Err(Error::invalid(
            "floquet",
            "cutoff",
            cutoff,
            format!(
                "finite for a model above {} DOFs (every mode needs a dense eigenproblem)",
                Model::MAX_DENSE_DOFS
            ),
        ));
    }
    let k0 = model.k0();
    let (r, next) = cache.below(model, &k0, cutoff, reach)?;
    // The shift from the first mode left out where it is known (the same for every cut-off
    // between two modes, so that the basis is too), else from the cut-off.
    let sigma = match next {
        Some(w2) if w2 > 0.0 && w2.is_finite() => 1e-4 * w2,
        _ => shift(model, &k0, cutoff),
    };
    // Unit forces on the element coordinates (the loads need none: see the module's docs).
    let mut forces: Vec<Vec<(usize, f64)>> = model
        .elements()
        .iter()
        .filter(|e| !e.law().is_linear_time_invariant())
        .map(|e| e.weights().to_vec())
        .collect();
    if r == 0 && forces.is_empty() {
        // No mode below the cut-off and no element: the loaded DOFs give the basis its
        // vectors (an empty one would have no multipliers at all).
        forces.extend(model.loaded_dofs().into_iter().map(|d| vec![(d, 1.0)]));
    }
    // The basis is that of the last call if the modes, the shift and the forces are.
    let key = {
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (r, sigma.to_bits()).hash(&mut h);
        for f in &forces {
            f.len().hash(&mut h);
            for &(i, w) in f {
                (i, w.to_bits()).hash(&mut h);
            }
        }
        h.finish()
    };
    if let Some((_, basis)) = cache.last.as_ref().filter(|(k, _)| *k == key) {
        return Ok(basis.clone());
    }
    let factor = ShiftedStiffness::new(&k0, model.mass(), sigma)?;
    let mut a = DMatrix::zeros(n, forces.len());
    for (c, f) in forces.iter().enumerate() {
        for &(i, w) in f {
            a[(i, c)] += w;
        }
    }
    factor.solve_in_place(&mut a);
    let mut v = cache.vectors.columns(0, r).into_owned();
    let mut kept = 0;
    for c in 0..a.ncols() {
        if v.ncols() >= n {
            break;
        }
        let mut x = a.column(c).into_owned();
        let before = m_norm(model, &x);
        if !(before > 0.0 && before.is_finite()) {
            continue;
        }
        for _ in 0..2 {
            let mx = m_times(model, &x);
            let coefficients = v.transpose() * &mx;
            x -= &v * coefficients;
        }
        let after = m_norm(model, &x);
        if after <= 1e-8 * before {
            continue;
        }
        x /= after;
        let last = v.ncols();
        v = v.insert_column(last, 0.0);
        v.set_column(last, &x);
        kept += 1;
    }
    let projected = std::sync::Arc::new(crate::stability::system::project_structure(model, &v));
    let basis = Basis {
        v,
        modes: r,
        attachment: kept,
        projected,
    };
    cache.last = Some((key, basis.clone()));
    Ok(basis)
}

fn m_times(model: &Model, x: &DVector<f64>) -> DVector<f64> {
    let mut out = DVector::zeros(x.len());
    model.mass().mul_add(1.0, x.as_slice(), out.as_mut_slice());
    out
}

fn m_norm(model: &Model, x: &DVector<f64>) -> f64 {
    x.dot(&m_times(model, x)).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::CubicSpring;

    /// A chain of 10 unit masses and springs, grounded at both ends, with a cubic spring
    /// between DOFs `a` and `a + 1` (no linear part: `K0` is the chain's whatever `a`) and a
    /// load on DOF 9.
    fn chain(a: usize) -> Model {
        let n = 10;
        let names: Vec<String> = (0..n).map(|i| format!("x{i}")).collect();
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        grounded_chain(&refs)
            .element(
                "spring",
                &[(refs[a], 1.0), (refs[a + 1], -1.0)],
                CubicSpring::new(0.0, 1.0),
            )
            .load(refs[n - 1], 1, 1.0, 0.0)
            .build()
            .unwrap()
    }

    /// Unit masses `refs` on unit springs between neighbours and to the ground at both ends.
    fn grounded_chain(refs: &[&str]) -> crate::model::ModelBuilder {
        let n = refs.len();
        let k = DMatrix::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 2.0,
            1 => -1.0,
            _ => 0.0,
        });
        Model::builder(refs)
            .mass_diagonal(&vec![1.0; n])
            .stiffness(k)
    }

    /// The kept basis is another model's only if the modes, the shift and the elements' unit
    /// forces agree: two models with the same M and K0 and the spring elsewhere
    /// get their own attachment modes from one cache.
    #[test]
    fn kept_basis_follows_the_elements() {
        let (a, b) = (chain(2), chain(6));
        let mut shared = ModeCache::default();
        let first = reduced_basis(&a, 1.0, 2.0, &mut shared).unwrap();
        let again = reduced_basis(&a, 1.0, 2.0, &mut shared).unwrap();
        assert_eq!(first.v, again.v);
        let kept = reduced_basis(&b, 1.0, 2.0, &mut shared).unwrap();
        let fresh = reduced_basis(&b, 1.0, 2.0, &mut ModeCache::default()).unwrap();
        assert_eq!(kept.v, fresh.v);
        assert!((&first.v - &fresh.v).abs().max() > 1e-3);
    }

    /// No attachment mode for a load, yet the element coordinate sees it exactly
    /// (reciprocity, module docs): the Galerkin solution of `K0 q = f` on the basis of three
    /// modes and the element's attachment mode gives the full model's `w_eᵀq` for a load at
    /// the far end of the chain to 6e-5 (the shift σ = 1e-4 ω₄²); the three modes alone are
    /// 93 % off.
    #[test]
    fn element_coordinates_see_a_static_load_without_its_attachment_mode() {
        let model = chain(2);
        let basis = reduced_basis(&model, 1.0, 2.0, &mut ModeCache::default()).unwrap();
        assert_eq!((basis.modes, basis.attachment), (3, 1));
        let k = model.k0().to_dense();
        let f = DVector::from_fn(10, |i, _| if i == 9 { 1.0 } else { 0.0 });
        let w = DVector::from_fn(10, |i, _| match i {
            2 => 1.0,
            3 => -1.0,
            _ => 0.0,
        });
        let exact = w.dot(&k.clone().lu().solve(&f).unwrap());
        let galerkin = |v: DMatrix<f64>| {
            let p = (v.transpose() * &k * &v)
                .lu()
                .solve(&(v.transpose() * &f))
                .unwrap();
            w.dot(&(v * p))
        };
        let reduced = galerkin(basis.v.clone());
        let modes = galerkin(basis.v.columns(0, basis.modes).into_owned());
        let relative = |a: f64| (a - exact).abs() / exact.abs();
        assert!(relative(reduced) < 1e-4, "{}", relative(reduced));
        assert!(relative(modes) > 0.5, "{}", relative(modes));
    }

    /// No mode below the cut-off and no element: the loaded DOF still gives the basis a
    /// vector (it would have none, and the analysis no multiplier).
    #[test]
    fn a_model_without_elements_below_its_first_mode_keeps_the_load() {
        let names: Vec<String> = (0..10).map(|i| format!("x{i}")).collect();
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let model = grounded_chain(&refs)
            .load(refs[9], 1, 1.0, 0.0)
            .build()
            .unwrap();
        let basis = reduced_basis(&model, 0.01, 0.02, &mut ModeCache::default()).unwrap();
        assert_eq!((basis.modes, basis.attachment, basis.v.ncols()), (0, 1, 1));
    }
}
