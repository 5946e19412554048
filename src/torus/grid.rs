//! The AFT on the d-torus: samples of `u(θ)` on an `N_1 × … × N_d` grid
//! `θ_j = (2π j_1/N_1, …, 2π j_d/N_d)` (row-major, the last base fastest) and the
//! multi-dimensional real FFT between them and the coefficients of an [`IndexSet`].
//!
//! Synthesis: the half spectrum `C(k) = Q_k/2` (`C(0) = Q_0`), placed at `k mod N` (or its
//! conjugate at `-k mod N` where the last entry of `k` is negative), inverse complex FFTs along
//! the first d-1 axes, then inverse real FFTs along the last:
//! `u(θ_j) = Re Σ_k Q_k e^{i k·θ_j}`. Analysis is the reverse with `Q_k = 2 C(k) / Π N_b`.
//! Planned once ([`TorusFft::new`]); the transforms allocate nothing ([`TorusScratch`]).

use super::IndexSet;
use crate::error::{Error, Result};
use num_complex::Complex64;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// Most samples on a torus grid (Π N_b): 2^22, 32 MiB per real sample buffer.
pub const MAX_GRID: usize = 1 << 22;

/// Where index `j`'s coefficient sits in the half spectrum.
#[derive(Debug, Clone, Copy)]
struct Slot {
    at: usize,
    conjugate: bool,
    /// Where `k` has last entry 0 (and `k ≠ 0`), `-k` is in the half spectrum too.
    mirror: Option<usize>,
}

/// Forward and inverse complex FFTs of one axis.
type AxisPlans = (Arc<dyn Fft<f64>>, Arc<dyn Fft<f64>>);

/// The planned transforms of one grid and index set. Cheap to clone (shared plans).
#[derive(Clone)]
pub struct TorusFft {
    dims: Vec<usize>,
    half: usize,
    rows: usize,
    slots: Vec<Slot>,
    /// Per axis a < d-1, the lines along it (by their position over the axes after a) that
    /// hold a coefficient of the set: the only ones synthesis finds nonzero and analysis
    /// needs (see [`TorusFft::along_axis`]).
    lines: Vec<Vec<usize>>,
    forward_rows: Arc<dyn RealToComplex<f64>>,
    inverse_rows: Arc<dyn ComplexToReal<f64>>,
    /// Forward and inverse complex FFTs along each axis but the last.
    axes: Vec<AxisPlans>,
    scratch_len: usize,
}

impl std::fmt::Debug for TorusFft {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TorusFft")
            .field("dims", &self.dims)
            .finish()
    }
}

/// Caller-owned buffers of [`TorusFft`].
#[derive(Debug, Clone)]
pub struct TorusScratch {
    spectrum: Vec<Complex64>,
    lines: Vec<Complex64>,
    fft: Vec<Complex64>,
}

impl TorusFft {
    /// Plans the transforms of `set` on a grid of `samples` (one `N_b >= 2H_b + 1` per base,
    /// at most [`MAX_GRID`] in all); an error names the base whose grid is too coarse.
    pub fn new(set: &IndexSet, samples: &[usize]) -> Result<Self> {
        let d = set.dims();
        if samples.len() != d {
            return Err(Error::DimensionMismatch {
                context: "torus grid (samples per base)".into(),
                expected: d.to_string(),
                got: samples.len().to_string(),
            });
        }
        for (b, (&n, &h)) in samples.iter().zip(set.caps()).enumerate() {
            if n < 2 * h + 1 || n < 2 {
                return Err(Error::InvalidElement {
                    context: format!("torus grid, base {}", b + 1),
                    reason: format!(
                        "{n} samples cannot resolve {h} harmonics: need at least {}",
                        (2 * h + 1).max(2)
                    ),
                });
            }
        }
        let total = samples.iter().try_fold(1usize, |a, &n| a.checked_mul(n));
        if total.is_none_or(|t| t > MAX_GRID) {
            return Err(Error::invalid(
                "torus grid",
                "samples",
                samples.iter().map(|&n| n as f64).product(),
                format!("<= {MAX_GRID} in all (the product over the bases)"),
            ));
        }
        let last = samples[d - 1];
        let half = last / 2 + 1;
        let rows: usize = samples[..d - 1].iter().product();
        let mut real = RealFftPlanner::<f64>::new();
        let mut complex = FftPlanner::<f64>::new();
        let forward_rows = real.plan_fft_forward(last);
        let inverse_rows = real.plan_fft_inverse(last);
        let axes: Vec<_> = samples[..d - 1]
            .iter()
            .map(|&n| (complex.plan_fft_forward(n), complex.plan_fft_inverse(n)))
            .collect();
        let scratch_len = axes
            .iter()
            .flat_map(|(f, i)| [f.get_inplace_scratch_len(), i.get_inplace_scratch_len()])
            .chain([
                forward_rows.get_scratch_len(),
                inverse_rows.get_scratch_len(),
            ])
            .max()
            .unwrap_or(0);
        let mut plan = Self {
            dims: samples.to_vec(),
            half,
            rows,
            slots: Vec::new(),
            lines: Vec::new(),
            forward_rows,
            inverse_rows,
            axes,
            scratch_len,
        };
        plan.slots = (0..set.len()).map(|j| plan.slot(set.k(j))).collect();
        plan.lines = (0..d - 1).map(|a| plan.lines_along(a)).collect();
        Ok(plan)
    }

    /// The samples per base `N_b`.
    pub fn dims(&self) -> &[usize] {
        &self.dims
    }

    /// Number of grid points `Π N_b`.
    pub fn points(&self) -> usize {
        self.rows * self.dims[self.dims.len() - 1]
    }

    /// Buffers for this plan.
    pub fn make_scratch(&self) -> TorusScratch {
        let len = self.rows * self.half;
        TorusScratch {
            spectrum: vec![Complex64::default(); len],
            lines: vec![Complex64::default(); len],
            fft: vec![Complex64::default(); self.scratch_len],
        }
    }

    /// The position of `k` (or of `-k`, conjugated) in the half spectrum.
    fn slot(&self, k: &[i32]) -> Slot {
        let d = k.len();
        let pos = |k: &[i32]| -> usize {
            let mut at = 0;
            for (&kb, &n) in k[..d - 1].iter().zip(&self.dims) {
                at = at * n + (kb as i64).rem_euclid(n as i64) as usize;
            }
            at * self.half + k[d - 1] as usize
        };
        let neg: Vec<i32> = k.iter().map(|v| -v).collect();
        match k[d - 1] {
            v if v > 0 => Slot {
                at: pos(k),
                conjugate: false,
                mirror: None,
            },
            v if v < 0 => Slot {
                at: pos(&neg),
                conjugate: true,
                mirror: None,
            },
            _ => Slot {
                at: pos(k),
                conjugate: false,
                mirror: k.iter().any(|&v| v != 0).then(|| pos(&neg)),
            },
        }
    }

    /// `out[j] = Re Σ_k c(k) e^{i k·θ_j}` over the grid, `c(k)` given per index position.
    pub fn synthesize_into(
        &self,
        coefficient: impl Fn(usize) -> Complex64,
        out: &mut [f64],
        s: &mut TorusScratch,
    ) {
        s.spectrum.fill(Complex64::default());
        for (j, slot) in self.slots.iter().enumerate() {
            let c = coefficient(j);
            // Index 0 is k = 0 (see [`IndexSet`]): a real mean.
            let c = if j == 0 {
                Complex64::new(c.re, 0.0)
            } else {
                0.5 * c
            };
            s.spectrum[slot.at] += if slot.conjugate { c.conj() } else { c };
            if let Some(m) = slot.mirror {
                s.spectrum[m] += c.conj();
            }
        }
        for a in 0..self.axes.len() {
            self.along_axis(a, false, s);
        }
        let last = self.dims[self.dims.len() - 1];
        for (row, out) in s.spectrum.chunks_mut(self.half).zip(out.chunks_mut(last)) {
            row[0].im = 0.0;
            if last % 2 == 0 {
                row[self.half - 1].im = 0.0;
            }
            // Cannot fail: lengths are the plan's and the imaginary parts that must vanish do.
            let _ = self.inverse_rows.process_with_scratch(row, out, &mut s.fft);
        }
    }

    /// The coefficients `Q_k` of the samples `x` (clobbered): `out(j, Q_j)` per index.
    pub fn analyze(
        &self,
        x: &mut [f64],
        s: &mut TorusScratch,
        mut out: impl FnMut(usize, Complex64),
    ) {
        let last = self.dims[self.dims.len() - 1];
        for (row, x) in s.spectrum.chunks_mut(self.half).zip(x.chunks_mut(last)) {
            let _ = self.forward_rows.process_with_scratch(x, row, &mut s.fft);
        }
        // The axes in reverse: each transform then only needs the lines that lead to a slot.
        for a in (0..self.axes.len()).rev() {
            self.along_axis(a, true, s);
        }
        let scale = 1.0 / self.points() as f64;
        for (j, slot) in self.slots.iter().enumerate() {
            let v = s.spectrum[slot.at];
            let v = if slot.conjugate { v.conj() } else { v };
            let two = if j == 0 { 1.0 } else { 2.0 };
            out(j, v * (two * scale));
        }
    }

    /// The stride of axis `a` (< d-1) in the half spectrum: the positions over the later axes.
    fn stride(&self, a: usize) -> usize {
        self.dims[a + 1..self.dims.len() - 1]
            .iter()
            .product::<usize>()
            * self.half
    }

    /// The lines along axis `a` that meet a slot, by their position over the later axes.
    fn lines_along(&self, a: usize) -> Vec<usize> {
        let stride = self.stride(a);
        let mut lines: Vec<usize> = self
            .slots
            .iter()
            .flat_map(|s| std::iter::once(s.at).chain(s.mirror))
            .map(|at| at % stride)
            .collect();
        lines.sort_unstable();
        lines.dedup();
        lines
    }

    /// The complex FFT along axis `a` (< d-1) of the half spectrum, in place, on the lines
    /// that meet a slot only. Synthesis transforms the axes in order 0, 1, …: before axis a,
    /// a line along it is nonzero only if its position over the later axes is a slot's (the
    /// earlier axes are transformed, the later ones not yet). Analysis transforms them in
    /// reverse, so that after axis a only the lines whose later positions lead to a slot are
    /// read again: the same lines.
    fn along_axis(&self, a: usize, forward: bool, s: &mut TorusScratch) {
        let n = self.dims[a];
        let stride = self.stride(a);
        let fft = if forward {
            &self.axes[a].0
        } else {
            &self.axes[a].1
        };
        let lines = &self.lines[a];
        let used = n * lines.len();
        for chunk in s.spectrum.chunks_mut(n * stride) {
            let buf = &mut s.lines[..used];
            for (line, &i) in buf.chunks_mut(n).zip(lines) {
                for (j, v) in line.iter_mut().enumerate() {
                    *v = chunk[j * stride + i];
                }
            }
            fft.process_with_scratch(buf, &mut s.fft);
            for (line, &i) in buf.chunks(n).zip(lines) {
                for (j, v) in line.iter().enumerate() {
                    chunk[j * stride + i] = *v;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::torus::{Bases, Truncation};
    use std::f64::consts::TAU;

    /// Synthesis equals the direct sum `Re Σ Q_k e^{i k·θ}` at every grid point, and analysis
    /// gives the coefficients back, in two and three dimensions with lines of every sign
    /// pattern (last entry positive, negative, zero).
    #[test]
    fn synthesis_is_the_direct_sum_and_analysis_inverts_it() {
        let cases: [(&[f64], &[usize], &[usize]); 2] = [
            (&[1.0, 2f64.sqrt()], &[3, 3], &[8, 7]),
            (&[0.5, 3f64.sqrt(), 5f64.sqrt()], &[2, 2, 1], &[5, 6, 4]),
        ];
        for (ratios, caps, dims) in cases {
            let named: Vec<(String, f64)> = ratios
                .iter()
                .enumerate()
                .map(|(b, &r)| (format!("b{b}"), r))
                .collect();
            let pairs: Vec<(&str, f64)> = named.iter().map(|(n, r)| (n.as_str(), *r)).collect();
            let bases = Bases::new(&pairs).unwrap();
            let set = IndexSet::new(&bases, caps, Truncation::Diamond { total: 3 }).unwrap();
            let fft = TorusFft::new(&set, dims).unwrap();
            let mut s = fft.make_scratch();
            let coef: Vec<Complex64> = (0..set.len())
                .map(|j| {
                    Complex64::new(
                        1.0 + j as f64,
                        if j == 0 { 0.0 } else { 0.3 * j as f64 - 1.0 },
                    )
                })
                .collect();
            let mut x = vec![0.0; fft.points()];
            fft.synthesize_into(|j| coef[j], &mut x, &mut s);
            for (p, xp) in x.iter().enumerate() {
                let mut rest = p;
                let mut theta = vec![0.0; dims.len()];
                for b in (0..dims.len()).rev() {
                    theta[b] = TAU * (rest % dims[b]) as f64 / dims[b] as f64;
                    rest /= dims[b];
                }
                let direct: f64 = (0..set.len())
                    .map(|j| {
                        let angle: f64 = set
                            .k(j)
                            .iter()
                            .zip(&theta)
                            .map(|(&k, t)| k as f64 * t)
                            .sum();
                        (coef[j] * Complex64::from_polar(1.0, angle)).re
                    })
                    .sum();
                assert!((direct - xp).abs() < 1e-12, "point {p}: {direct} vs {xp}");
            }
            let mut back = vec![Complex64::default(); set.len()];
            fft.analyze(&mut x, &mut s, |j, v| back[j] = v);
            for (j, (b, c)) in back.iter().zip(&coef).enumerate() {
                assert!((b - c).norm() < 1e-12, "line {:?}: {b} vs {c}", set.k(j));
            }
        }
    }
}
