//! The dynamic stiffness `Z_k = -(kΩ)² M + i kΩ D0 + K0` of a large model, held sparse and
//! factored by faer's sparse LU: one symbolic analysis (fill-reducing ordering, elimination
//! structure) for the common pattern of `M`, `D0`, `K0`, reused for every harmonic and every
//! speed; one numeric factorisation per harmonic.
//!
//! A drivetrain's matrices are chains and trees (a few nonzeros per row), so the factors stay
//! sparse and a factorisation costs `O(n)`, where the dense `LU` of
//! [`DynamicStiffness`](crate::harmonic::DynamicStiffness) costs `n³/3`.

use super::envelope::Envelope;
pub use super::sparse_pattern::{is_positive_definite, SparsePattern};
use crate::error::{Error, Result};
use crate::HarmonicBasis;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::SparseColMat;
use faer::MatMut;
use num_complex::Complex64;
use std::cell::RefCell;

/// One harmonic's factors: the envelope `L D Lᵀ` (a chain-like symmetric pattern) or faer's
/// pivoting sparse LU (anything else, or where the envelope meets a small pivot).
enum Factor {
    Envelope(Vec<Complex64>),
    Lu(Box<Lu<usize, Complex64>>),
}

/// `Z_k` for `k = 0..=H`, factored once per Ω: by the envelope `L D Lᵀ` in reverse
/// Cuthill–McKee order where the pattern is symmetric and its envelope small (drivetrains:
/// 30 to 50 times faster than a general sparse LU at 1000 DOFs), else by faer's sparse LU on
/// one symbolic analysis.
pub struct SparseDynamicStiffness {
    pattern: SparsePattern,
    /// The envelope and, per lower-triangle pattern entry, `(pattern index, envelope slot)`.
    envelope: Option<(Envelope, Vec<(usize, usize)>)>,
    /// faer's symbolic LU, made on first need.
    symbolic: Option<SymbolicLu<usize>>,
    fundamental: f64,
    factors: Vec<Factor>,
    work: RefCell<Vec<Complex64>>,
    /// The shift `σ` of the static factor `K0 + σM` (0 for a regular `K0`).
    shift: f64,
    /// Rigid-body modes of a free-free model: harmonic 0 solves in their complement.
    rigid: Option<std::sync::Arc<crate::model::RigidModes>>,
    /// `M`, `D0`, `K0` symmetric (to 1e-13): every `Z_k` is complex symmetric, `Z_kᵀ = Z_k`.
    symmetric: bool,
}

impl std::fmt::Debug for SparseDynamicStiffness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SparseDynamicStiffness")
            .field("n", &self.pattern.n)
            .field("nnz", &self.pattern.nnz())
            .field("envelope", &self.envelope.as_ref().map(|e| e.0.size()))
            .field("harmonics", &self.factors.len().saturating_sub(1))
            .finish()
    }
}

/// Normwise backward error `‖Z x - b‖ / (‖Z‖_F ‖x‖ + ‖b‖)` of a test solve above which a
/// factorisation is rejected (a stable one of a regular matrix gives about 1e-16 whatever its
/// condition; a singular matrix or a bad pivot gives a non-finite or large one).
const SINGULAR_RESIDUAL: f64 = 1e-8;

/// Largest envelope, in stored entries per pattern entry, for which `L D Lᵀ` is used.
const MAX_ENVELOPE_FILL: usize = 16;

impl SparseDynamicStiffness {
    /// Orders the pattern once (envelope or symbolic LU) and factors `Z_k` for every
    /// harmonic of `basis`; an error names the first singular harmonic.
    pub fn new(pattern: SparsePattern, basis: &HarmonicBasis) -> Result<Self> {
        Self::new_free(pattern, basis, None)
    }

    /// [`SparseDynamicStiffness::new`] for a free-free model with rigid-body modes `R` and the
    /// shift `σ` ([`RigidModes::shift`](crate::model::RigidModes::shift)): harmonic 0 is
    /// factored as `K0 + σM` and [`solve_in_place`](Self::solve_in_place) at k = 0 returns
    /// `K0⁺ x`, the solution of `K0 q = Πᵀ x` with `Rᵀ M q = 0` (`Πᵀ x = x - M R Rᵀ x`),
    /// by two steps of iterative refinement (each multiplies the error of mode `λ` by
    /// `σ/(λ + σ)`, about 1e-10).
    pub fn new_free(
        pattern: SparsePattern,
        basis: &HarmonicBasis,
        rigid: Option<(std::sync::Arc<crate::model::RigidModes>, f64)>,
    ) -> Result<Self> {
        let mut s = Self::ordered(pattern, basis.fundamental());
        if let Some((r, shift)) = rigid {
            s.rigid = Some(r);
            s.shift = shift;
        }
        s.refactor(basis)?;
        Ok(s)
    }

    /// `K0 + σM` alone (harmonic 0, no projection): for finding the rigid-body modes.
    pub fn shifted_static(pattern: SparsePattern, shift: f64) -> Result<Self> {
        let mut s = Self::ordered(pattern, 0.0);
        s.shift = shift;
        let f = s.factor(0, 0.0, true)?;
        s.factors.push(f);
        Ok(s)
    }

    /// `x ← (K0 + σM)⁻¹ x` in real arithmetic with the static factor.
    pub fn solve_static_real(&self, x: &mut [f64]) {
        let mut c: Vec<Complex64> = x.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        self.solve_with(&self.factors[0], &mut c, 1);
        for (xi, ci) in x.iter_mut().zip(&c) {
            *xi = ci.re;
        }
    }

    /// The ordering (envelope or none), nothing factored yet.
    fn ordered(pattern: SparsePattern, fundamental: f64) -> Self {
        let n = pattern.n;
        let symmetric = pattern.is_symmetric();
        let envelope = symmetric.then(|| {
            let (col_ptr, row_idx) = (&pattern.col_ptr, &pattern.row_idx);
            let entries = (0..n)
                .flat_map(move |j| (col_ptr[j]..col_ptr[j + 1]).map(move |p| (row_idx[p], j)));
            let env = Envelope::new(n, entries.clone());
            let slots: Vec<(usize, usize)> = entries
                .enumerate()
                .filter(|&(_, (i, j))| env.is_lower(i, j))
                .map(|(p, (i, j))| (p, env.position(i, j)))
                .collect();
            (env, slots)
        });
        let envelope =
            envelope.filter(|(env, _)| env.size() <= MAX_ENVELOPE_FILL * pattern.nnz() + n);
        Self {
            pattern,
            envelope,
            symbolic: None,
            fundamental,
            factors: Vec::new(),
            work: RefCell::new(vec![Complex64::default(); n]),
            shift: 0.0,
            rigid: None,
            symmetric,
        }
    }

    /// Factors `Z_k` again for another Ω (same ordering, same symbolic analysis).
    pub fn refactor(&mut self, basis: &HarmonicBasis) -> Result<()> {
        self.refactor_checked(basis, true)
    }

    /// [`refactor`](Self::refactor) without the test solve of every envelope factor above
    /// harmonic 0: the caller solves [`test_vector`](Self::test_vector) among its own
    /// right-hand sides and hands the result to [`verify`](Self::verify) before using a
    /// harmonic's factor (one more column in a multi-column solve instead of a solve of its
    /// own).
    pub fn refactor_unverified(&mut self, basis: &HarmonicBasis) -> Result<()> {
        self.refactor_checked(basis, false)
    }

    fn refactor_checked(&mut self, basis: &HarmonicBasis, verify: bool) -> Result<()> {
        self.fundamental = basis.fundamental();
        self.factors.clear();
        for k in 0..=basis.harmonics() {
            let f = self.factor(k, k as f64 * self.fundamental, verify || k == 0)?;
            self.factors.push(f);
        }
        Ok(())
    }

    /// The right-hand side `b = (1, 2, …, n)` of the backward-error test.
    pub fn test_vector(&self) -> impl Iterator<Item = Complex64> {
        (0..self.pattern.n).map(|i| Complex64::new(1.0 + i as f64, 0.0))
    }

    /// Checks harmonic `k`'s factor with `x = Z_k⁻¹ b` solved by the caller for the
    /// [`test_vector`](Self::test_vector) `b`: `Ok(true)` if its backward error is below
    /// the threshold (or the factor was checked when it was made); otherwise `Z_k` is factored
    /// again by the pivoting LU (checked) and `Ok(false)` asks the caller to solve again.
    pub fn verify(&mut self, k: usize, x: &[Complex64]) -> Result<bool> {
        if k == 0 || matches!(self.factors[k], Factor::Lu(_)) {
            return Ok(true);
        }
        let w = k as f64 * self.fundamental;
        let values = self.pattern.values(w, 0.0);
        if self.backward_error_of(x, w, 0.0, &values) < SINGULAR_RESIDUAL {
            return Ok(true);
        }
        self.factors[k] = self.lu_checked(k, w, values)?;
        Ok(false)
    }

    /// `Z_kᵀ = Z_k` for every k (symmetric `M`, `D0`, `K0`), so that
    /// `Wᵀ Z_k⁻¹ v = (Z_k⁻¹ W)ᵀ v`.
    pub fn is_symmetric(&self) -> bool {
        self.symmetric
    }

    /// The factor of `Z_k` at `w = kΩ` (`K0 + σM` at k = 0).
    fn factor(&mut self, k: usize, w: f64, verify: bool) -> Result<Factor> {
        {
            let s = if k == 0 { self.shift } else { 0.0 };
            let values = self.pattern.values(w, s);
            if values
                .iter()
                .any(|v| !(v.re.is_finite() && v.im.is_finite()))
            {
                return Err(crate::harmonic::non_finite_stiffness(k, w));
            }
            let mut factor = None;
            if let Some((env, slots)) = &self.envelope {
                let mut v = vec![Complex64::default(); env.size()];
                for &(p, slot) in slots {
                    v[slot] = values[p];
                }
                if env.factor(&mut v) {
                    let f = Factor::Envelope(v);
                    if !verify || self.backward_error(&f, w, s, &values) < SINGULAR_RESIDUAL {
                        factor = Some(f);
                    }
                }
            }
            match factor {
                Some(f) => Ok(f),
                None => self.lu_checked(k, w, values),
            }
        }
    }

    /// faer's pivoting LU of `values` (`Z_k` at `w`), rejected by its backward error.
    fn lu_checked(&mut self, k: usize, w: f64, values: Vec<Complex64>) -> Result<Factor> {
        let s = if k == 0 { self.shift } else { 0.0 };
        let f = self.lu(values.clone()).ok_or_else(|| singular(k, w, 0.0))?;
        let rel = self.backward_error(&f, w, s, &values);
        if rel.is_nan() || rel >= SINGULAR_RESIDUAL {
            return Err(singular(
                k,
                w,
                if rel.is_finite() { 1.0 / rel } else { 0.0 },
            ));
        }
        Ok(f)
    }

    /// faer's LU of the values on the pattern (symbolic analysis on first use).
    fn lu(&mut self, values: Vec<Complex64>) -> Option<Factor> {
        let structure = self.pattern.symbolic();
        if self.symbolic.is_none() {
            self.symbolic = SymbolicLu::try_new(structure.as_ref()).ok();
        }
        let symbolic = self.symbolic.clone()?;
        let z = SparseColMat::new(structure, values);
        Lu::try_new_with_symbolic(symbolic, z.as_ref())
            .ok()
            .map(|lu| Factor::Lu(Box::new(lu)))
    }

    /// The backward error of solving with `f` for `b = (1, 2, ..., n)`.
    fn backward_error(&self, f: &Factor, w: f64, s: f64, values: &[Complex64]) -> f64 {
        let mut x: Vec<Complex64> = self.test_vector().collect();
        self.solve_with(f, &mut x, 1);
        self.backward_error_of(&x, w, s, values)
    }

    /// The backward error of `x` as the solution for the test vector.
    fn backward_error_of(&self, x: &[Complex64], w: f64, s: f64, values: &[Complex64]) -> f64 {
        let n = self.pattern.n;
        let b: Vec<Complex64> = self.test_vector().collect();
        let mut back = vec![Complex64::default(); n];
        self.pattern.apply(w, s, x, &mut back);
        let norm = |v: &[Complex64]| v.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt();
        let err = back
            .iter()
            .zip(&b)
            .map(|(a, c)| (a - c).norm_sqr())
            .sum::<f64>()
            .sqrt();
        let rel = err / (norm(values) * norm(x) + norm(&b));
        if rel.is_finite() {
            rel
        } else {
            f64::INFINITY
        }
    }

    fn solve_with(&self, f: &Factor, x: &mut [Complex64], columns: usize) {
        let n = self.pattern.n;
        match f {
            Factor::Lu(lu) => lu.solve_in_place(MatMut::from_column_major_slice_mut(x, n, columns)),
            Factor::Envelope(v) => {
                let Some((env, _)) = &self.envelope else {
                    return;
                };
                let mut work = self.work.borrow_mut();
                if work.len() < n * columns {
                    work.resize(n * columns, Complex64::default());
                }
                env.solve(v, x, columns, &mut work);
            }
        }
    }

    /// Order n.
    pub fn n(&self) -> usize {
        self.pattern.n
    }

    /// Harmonics H factored.
    pub fn harmonics(&self) -> usize {
        self.factors.len().saturating_sub(1)
    }

    /// `x ← Z_k⁻¹ x` for `columns` right-hand sides stored one after the other (column-major
    /// `n × columns`).
    /// At k = 0 of a free-free model: `K0⁺ x` per column (see [`Self::new_free`]).
    pub fn solve_in_place(&self, k: usize, x: &mut [Complex64], columns: usize) {
        match (&self.rigid, k) {
            (Some(rigid), 0) => {
                let n = self.pattern.n;
                for col in x.chunks_mut(n).take(columns) {
                    self.solve_free(rigid, col);
                }
            }
            _ => self.solve_with(&self.factors[k], x, columns),
        }
    }

    /// `x ← K0⁺ x` in the complement of the rigid-body modes: `b = Πᵀ x`,
    /// `q ← Π (K0 + σM)⁻¹ b`, then twice `q ← q + Π (K0 + σM)⁻¹ (b - K0 q)`.
    fn solve_free(&self, rigid: &crate::model::RigidModes, x: &mut [Complex64]) {
        rigid.project_load(x);
        let b = x.to_vec();
        let mut r = vec![Complex64::default(); x.len()];
        self.solve_with(&self.factors[0], x, 1);
        rigid.project_motion(x);
        for _ in 0..2 {
            self.pattern.apply(0.0, 0.0, x, &mut r);
            for (ri, bi) in r.iter_mut().zip(&b) {
                *ri = bi - *ri;
            }
            self.solve_with(&self.factors[0], &mut r, 1);
            rigid.project_motion(&mut r);
            for (xi, ri) in x.iter_mut().zip(&r) {
                *xi += ri;
            }
        }
    }

    /// The rigid-body modes harmonic 0 is solved in the complement of (free-free models).
    pub fn rigid_modes(&self) -> Option<&std::sync::Arc<crate::model::RigidModes>> {
        self.rigid.as_ref()
    }

    /// How many harmonics use the envelope `L D Lᵀ` (the rest use the sparse LU).
    pub fn envelope_harmonics(&self) -> usize {
        self.factors
            .iter()
            .filter(|f| matches!(f, Factor::Envelope(_)))
            .count()
    }

    /// `out ← (dZ_k/dΩ) x`, where harmonic k oscillates at `k Ω / ν` (`kappa = k/ν`) and
    /// `omega` is Ω.
    pub fn apply_omega_derivative(
        &self,
        kappa: f64,
        omega: f64,
        x: &[Complex64],
        out: &mut [Complex64],
    ) {
        self.pattern.apply_omega_derivative(kappa, omega, x, out);
    }

    /// `out ← Z_k x`.
    pub fn apply(&self, k: usize, x: &[Complex64], out: &mut [Complex64]) {
        self.pattern.apply(k as f64 * self.fundamental, 0.0, x, out);
    }
}

/// The error of a singular `Z_k` at frequency `w`.
fn singular(k: usize, w: f64, relative_pivot: f64) -> Error {
    let hint = if k == 0 {
        "K0 is singular, but not by a free rigid-body mode (free-free models are handled): a motion held only by damping to ground or by an element without linear stiffness, or a massless DOF; ground it with a stiffness or fix the DOF"
            .to_string()
    } else {
        format!(
            "an undamped natural frequency at {w} rad/s coincides with harmonic {k}; add damping or shift the speed"
        )
    };
    Error::SingularDynamicStiffness {
        harmonic: k,
        omega: w,
        relative_pivot,
        hint,
    }
}
