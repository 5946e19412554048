//! The index set `K ⊂ Z^d` of a multi-frequency Fourier basis: the response is
//! `q(θ) = Re Σ_{k ∈ K} Q_k e^{i k·θ}` on the torus `θ ∈ [0, 2π)^d`, at time t on the line
//! `θ_b = ω_b t`, so that `Q_k` oscillates at `ν_k = k·ω = Ω (k·r)`.
//!
//! A real signal needs only half of `Z^d`: `K` holds `k = 0` and the `k` with `k·r > 0`
//! (each line at a positive frequency once; `-k` is its conjugate). Truncations: a box
//! `|k_b| <= H_b`, or a total-degree "diamond" `Σ|k_b| <= H` inside the box (the combination
//! tones of low total order, the ones a weak coupling excites first).

use super::Bases;
use crate::error::{Error, Result};

/// How the index set is truncated inside its per-base caps `|k_b| <= H_b`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Truncation {
    /// Every `k` with `|k_b| <= H_b`.
    Box,
    /// In the box, only `Σ_b |k_b| <= total`.
    Diamond {
        /// The largest total degree.
        total: usize,
    },
}

/// One index `k` (the first d entries are used).
pub type Index = [i32; Bases::MAX];

/// The index set: `k = 0` first, then by ascending frequency `k·r`.
#[derive(Debug, Clone, PartialEq)]
pub struct IndexSet {
    d: usize,
    /// The ratios of the bases it was built for.
    base_ratios: Vec<f64>,
    caps: Vec<usize>,
    truncation: Truncation,
    indices: Vec<Index>,
    /// `k·r` per index.
    ratios: Vec<f64>,
}

impl IndexSet {
    /// Most indices in a set (each costs a complex unknown per coordinate and a factored
    /// dynamic stiffness).
    pub const MAX_INDICES: usize = 1 << 18;

    /// Largest cap `H_b` of one base.
    pub const MAX_CAP: usize = 1 << 12;

    /// The set of `bases` with caps `H_b` (one per base) and `truncation`. An error (before
    /// anything is allocated) for a cap count that differs from d, a cap above
    /// [`IndexSet::MAX_CAP`], a set above [`IndexSet::MAX_INDICES`], or two indices the
    /// bases cannot tell apart (a `k ≠ 0` in the box with `k·r = 0`: the bases are
    /// commensurate at these orders, so the common period is short enough for one
    /// fundamental).
    ///
    /// ```
    /// use hbal::torus::{Bases, IndexSet, Truncation};
    /// let b = Bases::new(&[("a", 1.0), ("b", 2f64.sqrt())]).unwrap();
    /// let set = IndexSet::new(&b, &[2, 2], Truncation::Diamond { total: 2 }).unwrap();
    /// // k = 0 and the six of the thirteen with Σ|k_b| <= 2 at a positive frequency:
    /// assert_eq!(set.len(), 7);
    /// assert_eq!(set.k(0), &[0, 0]);
    /// assert!((set.ratio(1) - (2f64.sqrt() - 1.0)).abs() < 1e-15); // (-1, 1) comes first
    /// ```
    pub fn new(bases: &Bases, caps: &[usize], truncation: Truncation) -> Result<Self> {
        let d = bases.len();
        if caps.len() != d {
            return Err(Error::DimensionMismatch {
                context: "torus harmonics (one cap per base)".into(),
                expected: d.to_string(),
                got: caps.len().to_string(),
            });
        }
        for (b, &c) in caps.iter().enumerate() {
            if c > Self::MAX_CAP {
                return Err(Error::invalid(
                    format!("torus base `{}`", bases.names()[b]),
                    "harmonics",
                    c as f64,
                    format!("<= {}", Self::MAX_CAP),
                ));
            }
        }
        let boxed: f64 = caps.iter().map(|&c| (2 * c + 1) as f64).product();
        let estimate = match truncation {
            Truncation::Box => boxed / 2.0,
            Truncation::Diamond { total } => boxed.min(diamond_count(d, total)) / 2.0,
        };
        if estimate > Self::MAX_INDICES as f64 {
            return Err(Error::invalid(
                "torus harmonics",
                "index set size",
                estimate.ceil(),
                format!(
                    "<= {} indices: lower the caps or use a diamond truncation",
                    Self::MAX_INDICES
                ),
            ));
        }
        let r = bases.ratios();
        let budget = match truncation {
            Truncation::Box => usize::MAX,
            Truncation::Diamond { total } => total,
        };
        let mut all = Vec::new();
        enumerate(caps, budget, &mut [0; Bases::MAX], 0, &mut all);
        let mut entries: Vec<(Index, f64)> = Vec::with_capacity(all.len() / 2 + 1);
        for k in all {
            let ratio: f64 = (0..d).map(|b| k[b] as f64 * r[b]).sum();
            let scale: f64 = (0..d).map(|b| (k[b] as f64 * r[b]).abs()).sum();
            if k[..d].iter().all(|&v| v == 0) {
                entries.push((k, 0.0));
            } else if ratio.abs() <= 1e-10 * scale {
                return Err(commensurate(bases, &k[..d]));
            } else if ratio > 0.0 {
                entries.push((k, ratio));
            }
        }
        entries.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        Ok(Self {
            d,
            base_ratios: r.to_vec(),
            caps: caps.to_vec(),
            truncation,
            indices: entries.iter().map(|e| e.0).collect(),
            ratios: entries.iter().map(|e| e.1).collect(),
        })
    }

    /// Number of indices.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// `false`: a set always holds `k = 0`.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Number of bases d.
    pub fn dims(&self) -> usize {
        self.d
    }

    /// The ratios `r_b` of the bases the set was built for.
    pub fn base_ratios(&self) -> &[f64] {
        &self.base_ratios
    }

    /// The caps `H_b`.
    pub fn caps(&self) -> &[usize] {
        &self.caps
    }

    /// The truncation.
    pub fn truncation(&self) -> Truncation {
        self.truncation
    }

    /// Index `j` as its d integers.
    pub fn k(&self, j: usize) -> &[i32] {
        &self.indices[j][..self.d]
    }

    /// `k·r` of index `j`: its frequency over the speed (0 for `k = 0`, positive otherwise).
    pub fn ratio(&self, j: usize) -> f64 {
        self.ratios[j]
    }

    /// The position of `k` (d integers) in the set, if it is there; `-k` is found as `k`'s
    /// conjugate by the caller.
    pub fn position(&self, k: &[i32]) -> Option<usize> {
        self.indices.iter().position(|i| &i[..self.d] == k)
    }

    /// Whether `k` lies inside the truncation (either sign).
    pub fn contains_either_sign(&self, k: &[i32]) -> bool {
        let degree: usize = k.iter().map(|v| v.unsigned_abs() as usize).sum();
        k.iter()
            .zip(&self.caps)
            .all(|(v, &c)| v.unsigned_abs() as usize <= c)
            && match self.truncation {
                Truncation::Box => true,
                Truncation::Diamond { total } => degree <= total,
            }
    }
}

/// Every `k` with `|k_b| <= caps[b]` from base `b` on and `Σ_{i >= b} |k_i| <= budget`, the
/// entries before `b` as in `k`, into `out`: the diamond without walking its box.
fn enumerate(caps: &[usize], budget: usize, k: &mut Index, b: usize, out: &mut Vec<Index>) {
    if b == caps.len() {
        out.push(*k);
        return;
    }
    let reach = caps[b].min(budget) as i32;
    for v in -reach..=reach {
        k[b] = v;
        enumerate(caps, budget - v.unsigned_abs() as usize, k, b + 1, out);
    }
    k[b] = 0;
}

/// The number of `k ∈ Z^d` with `Σ|k_b| <= h` (an upper bound inside a box).
fn diamond_count(d: usize, h: usize) -> f64 {
    // Σ_i 2^i C(d, i) C(h, i).
    let choose = |n: usize, k: usize| -> f64 {
        if k > n {
            return 0.0;
        }
        (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
    };
    (0..=d)
        .map(|i| 2f64.powi(i as i32) * choose(d, i) * choose(h, i))
        .sum()
}

/// The error for an index with `k·r = 0`.
fn commensurate(bases: &Bases, k: &[i32]) -> Error {
    let combination: Vec<String> = k
        .iter()
        .zip(bases.names())
        .filter(|(v, _)| **v != 0)
        .map(|(v, n)| format!("{v}·{n}"))
        .collect();
    Error::InvalidElement {
        context: "torus harmonics".into(),
        reason: format!(
            "the combination {} has frequency zero: the bases are commensurate at these orders (their common period is short), so one fundamental represents the response; lower the caps below this combination or use the one-frequency basis",
            combination.join(" + ")
        ),
    }
}
