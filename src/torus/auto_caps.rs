//! Automatic caps: each base's cap is raised until its truncation estimate
//! ([`TorusSolution::truncation`]) is below a tolerance, every level warm-started from the one
//! before (the lines both sets share keep their values).

use super::{IndexSet, NewtonKrylov, TorusBalance, TorusModel, TorusSolution, Truncation};
use crate::error::Result;
use num_complex::Complex64;
use std::collections::HashMap;

/// The settings of automatic caps.
///
/// A base whose estimate `e_b` is above `tolerance` gets the cap `⌈3 H_b / 2⌉` (at least
/// `H_b + 2`) and a grid of the next power of two `>= 2 H_b + 3`; the others keep theirs. It
/// stops when every estimate is below the tolerance, or at `max_cap`, `max_lines` or
/// `max_levels`, saying why.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AutoCaps {
    /// Largest accepted estimate of any base (relative to the alternating response).
    pub tolerance: f64,
    /// Largest cap of a base.
    pub max_cap: usize,
    /// Largest number of lines.
    pub max_lines: usize,
    /// Largest number of levels (solves).
    pub max_levels: usize,
}

impl Default for AutoCaps {
    fn default() -> Self {
        Self {
            tolerance: 1e-3,
            max_cap: 64,
            max_lines: 20_000,
            max_levels: 8,
        }
    }
}

/// One level of automatic caps.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CapsLevel {
    /// The caps.
    pub caps: Vec<usize>,
    /// Grid points per base.
    pub samples: Vec<usize>,
    /// Lines of the index set.
    pub lines: usize,
    /// The estimate of every base (`None`: not estimated).
    pub estimates: Vec<Option<f64>>,
    /// Whether the solve converged.
    pub converged: bool,
}

/// The last level's solution, the levels, and why it stopped short of the tolerance.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AutoCapsOutcome {
    /// The solution at the last level.
    pub solution: TorusSolution,
    /// The last level's caps and grid.
    pub caps: Vec<usize>,
    /// Grid points per base of the last level.
    pub samples: Vec<usize>,
    /// The last level's truncation (a diamond's total grows with the caps).
    pub truncation: Truncation,
    /// Every level in order.
    pub levels: Vec<CapsLevel>,
    /// `None` if every estimate is below the tolerance, else why it stopped.
    pub stopped: Option<String>,
}

impl AutoCaps {
    /// Solves `tm` at the speed `omega` from the caps `caps` on the grid `samples`, raising
    /// caps as above.
    pub fn solve(
        &self,
        tm: &TorusModel,
        caps: &[usize],
        samples: &[usize],
        truncation: Truncation,
        omega: f64,
        solver: &NewtonKrylov,
    ) -> Result<AutoCapsOutcome> {
        let (mut caps, mut samples, mut truncation) = (caps.to_vec(), samples.to_vec(), truncation);
        let mut levels = Vec::new();
        let mut previous: Option<(IndexSet, TorusSolution)> = None;
        loop {
            let set = IndexSet::new(tm.bases(), &caps, truncation)?;
            let hb = TorusBalance::new(tm.clone(), set.clone(), &samples, omega)?;
            let start = previous.as_ref().map(|(old, sol)| carry(old, sol, &set));
            let solution = solver.solve(&hb, start.as_deref())?;
            levels.push(CapsLevel {
                caps: caps.clone(),
                samples: samples.clone(),
                lines: set.len(),
                estimates: solution.truncation.clone(),
                converged: solution.converged,
            });
            if !solution.converged {
                // A usable converged level is not thrown away for a failed finer one.
                if let Some((old, prior)) = previous {
                    let last = &levels[levels.len() - 2];
                    return Ok(AutoCapsOutcome {
                        stopped: Some(format!(
                            "the solve at caps {caps:?} did not converge; the caps {:?} before it are reported",
                            last.caps
                        )),
                        caps: last.caps.clone(),
                        samples: last.samples.clone(),
                        truncation: old.truncation(),
                        solution: prior,
                        levels,
                    });
                }
            }
            let raise =
                match self.verdict(&solution, &caps, &samples, tm.bases().names(), levels.len()) {
                    Ok(raise) if !raise.is_empty() => raise,
                    verdict => {
                        let stopped = verdict.err();
                        return Ok(AutoCapsOutcome {
                            solution,
                            caps,
                            samples,
                            truncation,
                            levels,
                            stopped,
                        });
                    }
                };
            let mut grown = 0;
            for &b in &raise {
                let cap = (3 * caps[b]).div_ceil(2).max(caps[b] + 2).min(self.max_cap);
                grown = grown.max(cap - caps[b]);
                caps[b] = cap;
                samples[b] = samples[b].max((2 * cap + 3).next_power_of_two());
            }
            if let Truncation::Diamond { total } = truncation {
                truncation = Truncation::Diamond {
                    total: total + grown,
                };
            }
            let next = IndexSet::new(tm.bases(), &caps, truncation)?;
            if next.len() > self.max_lines {
                let stopped = Some(format!(
                    "the next caps {caps:?} need {} lines, more than {}",
                    next.len(),
                    self.max_lines
                ));
                let (caps, samples) = (
                    levels[levels.len() - 1].caps.clone(),
                    levels[levels.len() - 1].samples.clone(),
                );
                return Ok(AutoCapsOutcome {
                    solution,
                    caps,
                    samples,
                    truncation: set.truncation(),
                    levels,
                    stopped,
                });
            }
            previous = Some((set, solution));
        }
    }
}

impl AutoCaps {
    /// The bases to raise after a level, or why to stop.
    fn verdict(
        &self,
        solution: &TorusSolution,
        caps: &[usize],
        samples: &[usize],
        names: &[String],
        levels: usize,
    ) -> std::result::Result<Vec<usize>, String> {
        if !solution.converged {
            return Err(format!("the solve at caps {caps:?} did not converge"));
        }
        let mut raise = Vec::new();
        for (b, e) in solution.truncation.iter().enumerate() {
            match e {
                None => return Err(format!("base `{}` has no estimate (its grid of {} points cannot hold one more harmonic, or a combination of frequency zero lies just beyond the caps)", names[b], samples[b])),
                Some(e) if *e > self.tolerance => raise.push(b),
                Some(_) => {}
            }
        }
        if let Some(&b) = raise.iter().find(|&&b| caps[b] >= self.max_cap) {
            return Err(format!(
                "base `{}` is at the largest cap {} (harmonics.max)",
                names[b], self.max_cap
            ));
        }
        if !raise.is_empty() && levels >= self.max_levels {
            return Err(format!("{} levels solved", self.max_levels));
        }
        Ok(raise)
    }
}

/// The unknowns of `sol` (on `old`) placed on the lines of `new`; new lines start at 0.
fn carry(old: &IndexSet, sol: &TorusSolution, new: &IndexSet) -> Vec<Complex64> {
    let m = sol.unknowns.len() / old.len().max(1);
    let at: HashMap<&[i32], usize> = (0..old.len()).map(|j| (old.k(j), j)).collect();
    let mut u = vec![Complex64::default(); new.len() * m];
    for j in 0..new.len() {
        if let Some(&o) = at.get(new.k(j)) {
            for c in 0..m {
                let (re, im) = sol.unknowns[o * m + c];
                u[j * m + c] = Complex64::new(re, im);
            }
        }
    }
    u
}
