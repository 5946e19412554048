//! Factoring `Z_k = -(kΩ)² M + i kΩ D0 + K0` of a [`SparseDynamicStiffness`] for every
//! harmonic of a speed: the envelope `L D Lᵀ` without pivoting where it is stable, checked by
//! the normwise backward error of a test solve `‖Z x - b‖ / (‖Z‖_F ‖x‖ + ‖b‖)` (about 1e-16 for
//! a stable factor whatever the condition; a bad pivot or a singular `Z_k` gives a large or
//! non-finite one), else faer's pivoting sparse LU on one symbolic analysis; the harmonics on
//! the cores ([`parallel`](super::parallel)).

use super::sparse_stiffness::{Factor, SparseDynamicStiffness};
use crate::error::{Error, Result};
use crate::HarmonicBasis;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::SparseColMat;
use num_complex::Complex64;

/// Normwise backward error `‖Z x - b‖ / (‖Z‖_F ‖x‖ + ‖b‖)` of a test solve above which a
/// factorisation is rejected (a stable one of a regular matrix gives about 1e-16 whatever its
/// condition; a singular matrix or a bad pivot gives a non-finite or large one).
const SINGULAR_RESIDUAL: f64 = 1e-8;

impl SparseDynamicStiffness {
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

    /// Every harmonic's envelope factor on the cores ([`parallel`](super::parallel)), then the
    /// pivoting LU where the envelope is not usable.
    fn refactor_checked(&mut self, basis: &HarmonicBasis, verify: bool) -> Result<()> {
        let fundamental = basis.fundamental();
        self.fundamental = fundamental;
        let count = basis.harmonics() + 1;
        // The last factors' storage, filled again (no fresh pages per speed).
        let mut storage: Vec<Vec<Complex64>> = std::mem::take(&mut self.factors)
            .into_iter()
            .map(|f| match f {
                Factor::Envelope(v) => v,
                Factor::Lu(_) => Vec::new(),
            })
            .collect();
        storage.resize_with(count, Vec::new);
        let this = &*self;
        let threads = super::parallel::threads(self.pattern.n * count);
        let made = super::parallel::map_owned(storage, threads, |k, v| {
            this.envelope_factor(k, k as f64 * fundamental, verify || k == 0, v)
        });
        for (k, made) in made.into_iter().enumerate() {
            let f = match made? {
                Some(f) => f,
                None => {
                    let w = k as f64 * fundamental;
                    let s = if k == 0 { self.shift } else { 0.0 };
                    let values = self.pattern.values(w, s);
                    self.lu_checked(k, w, values)?
                }
            };
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
        if self.check(k, x) {
            return Ok(true);
        }
        let w = k as f64 * self.fundamental;
        let values = self.pattern.values(w, 0.0);
        self.factors[k] = self.lu_checked(k, w, values)?;
        Ok(false)
    }

    /// The test of [`verify`](Self::verify) alone: `true` if harmonic `k`'s factor passes.
    pub fn check(&self, k: usize, x: &[Complex64]) -> bool {
        if k == 0 || matches!(self.factors[k], Factor::Lu(_)) {
            return true;
        }
        let w = k as f64 * self.fundamental;
        self.backward_error_of(x, w, 0.0, self.pattern.values_norm(w, 0.0)) < SINGULAR_RESIDUAL
    }

    /// `Z_kᵀ = Z_k` for every k (symmetric `M`, `D0`, `K0`), so that
    /// `Wᵀ Z_k⁻¹ v = (Z_k⁻¹ W)ᵀ v`.
    pub fn is_symmetric(&self) -> bool {
        self.symmetric
    }

    /// The factor of `Z_k` at `w = kΩ` (`K0 + σM` at k = 0).
    pub(super) fn factor(&mut self, k: usize, w: f64, verify: bool) -> Result<Factor> {
        match self.envelope_factor(k, w, verify, Vec::new())? {
            Some(f) => Ok(f),
            None => {
                let s = if k == 0 { self.shift } else { 0.0 };
                let values = self.pattern.values(w, s);
                self.lu_checked(k, w, values)
            }
        }
    }

    /// The envelope `L D Lᵀ` of `Z_k` at `w`, `None` where there is no envelope, a zero pivot
    /// or (with `verify`) a backward error above the threshold; an error for non-finite values.
    ///
    /// `v` is storage to fill (a factor of the last speed, or empty).
    fn envelope_factor(
        &self,
        k: usize,
        w: f64,
        verify: bool,
        mut v: Vec<Complex64>,
    ) -> Result<Option<Factor>> {
        let s = if k == 0 { self.shift } else { 0.0 };
        let norm = self.pattern.values_norm(w, s);
        if norm.is_nan() {
            return Err(crate::harmonic::non_finite_stiffness(k, w));
        }
        let Some((env, slots)) = &self.envelope else {
            return Ok(None);
        };
        v.clear();
        v.resize(env.size(), Complex64::default());
        for &(p, slot) in slots {
            v[slot] = self.pattern.value(p, w, s);
        }
        if !env.factor(&mut v) {
            return Ok(None);
        }
        let f = Factor::Envelope(v);
        Ok((!verify || self.backward_error(&f, w, s, norm) < SINGULAR_RESIDUAL).then_some(f))
    }

    /// faer's pivoting LU of `values` (`Z_k` at `w`), rejected by its backward error.
    fn lu_checked(&mut self, k: usize, w: f64, values: Vec<Complex64>) -> Result<Factor> {
        let s = if k == 0 { self.shift } else { 0.0 };
        let norm = self.pattern.values_norm(w, s);
        let f = self.lu(values).ok_or_else(|| singular(k, w, 0.0))?;
        let rel = self.backward_error(&f, w, s, norm);
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
    /// (`norm` = `‖Z‖_F`, [`values_norm`](super::sparse_pattern::SparsePattern::values_norm).)
    fn backward_error(&self, f: &Factor, w: f64, s: f64, norm: f64) -> f64 {
        let mut x: Vec<Complex64> = self.test_vector().collect();
        self.solve_with(f, &mut x, 1);
        self.backward_error_of(&x, w, s, norm)
    }

    /// The backward error of `x` as the solution for the test vector (`values_norm` =
    /// `‖Z‖_F`).
    fn backward_error_of(&self, x: &[Complex64], w: f64, s: f64, values_norm: f64) -> f64 {
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
        let rel = err / (values_norm * norm(x) + norm(&b));
        if rel.is_finite() {
            rel
        } else {
            f64::INFINITY
        }
    }
}

/// The error of a singular `Z_k` at frequency `w`.
fn singular(k: usize, w: f64, relative_pivot: f64) -> Error {
    let hint = if k == 0 {
        "K0 is singular, but not by a rigid-body mode (free-free models and motions held only by damping to ground are handled): a motion held only by an element without linear stiffness, or a massless DOF; ground it with a stiffness or fix the DOF"
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
