//! Speed sweeps on the torus: every base keeps its ratio to the speed Ω, which is the
//! parameter; each point starts from the last converged one (natural continuation).

use super::{NewtonKrylov, TorusBalance, TorusSolution};
use crate::error::{Error, Result};
use num_complex::Complex64;

/// What the sweep says about stability.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case", tag = "status")]
pub enum TorusStability {
    /// Not computed, with the reason.
    NotComputed {
        /// Why.
        reason: String,
    },
}

impl TorusStability {
    /// The statement for a quasi-periodic response.
    pub fn quasi_periodic() -> Self {
        Self::NotComputed {
            reason: "not computed: a response on several base frequencies has no period, so no Floquet multipliers (Lyapunov exponents along the torus are not implemented); a commensurate train can be checked over its common period with the one-frequency engine".into(),
        }
    }
}

/// A speed sweep: [`NewtonKrylov`] at every speed, warm-started from the last converged
/// point; a point that does not converge from there is solved again from the linear response
/// (a run-up jumps where a branch ends, as a time integration does), then by
/// [`TorusBroyden`](super::TorusBroyden) from the warm start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusSweep {
    /// The solver at each point.
    pub solver: NewtonKrylov,
    /// Most Broyden steps at a point where Newton–Krylov fails (0: no fallback).
    pub broyden_fallback: usize,
}

impl Default for TorusSweep {
    fn default() -> Self {
        Self {
            solver: NewtonKrylov::default(),
            broyden_fallback: 200,
        }
    }
}

/// The sweep's points in order, the speeds where the balance could not be set up (a line on
/// an undamped resonance), and the stability statement.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TorusSweepResult {
    /// The points (converged or marked).
    pub points: Vec<TorusSolution>,
    /// `(Ω, message)` where no point could be computed.
    pub skipped: Vec<(f64, String)>,
    /// Stability.
    pub stability: TorusStability,
}

impl TorusSweepResult {
    /// Points that did not reach the tolerance, and skipped speeds.
    pub fn failures(&self) -> usize {
        self.points.iter().filter(|p| !p.converged).count() + self.skipped.len()
    }
}

impl TorusSweep {
    /// Sweeps `hb` over `speeds` (rad/s, in the order given); `progress(i, point)` after each
    /// point. Bad speeds (not finite, not positive, outside a load's table over speed) are an
    /// error before any work.
    pub fn run(
        &self,
        hb: &mut TorusBalance,
        speeds: &[f64],
        mut progress: impl FnMut(usize, &TorusSolution),
    ) -> Result<TorusSweepResult> {
        if speeds.is_empty() {
            return Err(Error::InvalidOptions {
                option: "torus sweep".into(),
                reason: "needs at least one speed".into(),
            });
        }
        for &w in speeds {
            crate::harmonic::HarmonicBasis::new(w, 0)?;
        }
        let lo = speeds.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = speeds.iter().copied().fold(0.0, f64::max);
        hb.torus_model().model().check_load_speeds(lo, hi)?;
        let mut points = Vec::with_capacity(speeds.len());
        let mut skipped = Vec::new();
        let mut start: Option<Vec<Complex64>> = None;
        for (i, &w) in speeds.iter().enumerate() {
            if let Err(e) = hb.set_omega(w) {
                skipped.push((w, e.to_string()));
                continue;
            }
            let mut sol = self.solver.solve(hb, start.as_deref())?;
            if !sol.converged && start.is_some() {
                let fresh = self.solver.solve(hb, None)?;
                if fresh.converged || fresh.relative_residual < sol.relative_residual {
                    sol = fresh;
                }
            }
            if !sol.converged && self.broyden_fallback > 0 {
                // Broyden's secant steps get through some places where a contact opens and
                // Newton's line search stalls.
                let broyden = super::TorusBroyden {
                    tolerance: self.solver.tolerance,
                    max_iterations: self.broyden_fallback,
                    ..Default::default()
                };
                let b = broyden.solve(hb, start.as_deref())?;
                if b.converged || b.relative_residual < sol.relative_residual {
                    sol = b;
                }
            }
            if sol.converged {
                start = Some(
                    sol.unknowns
                        .iter()
                        .map(|&(a, b)| Complex64::new(a, b))
                        .collect(),
                );
            }
            progress(i, &sol);
            points.push(sol);
        }
        Ok(TorusSweepResult {
            points,
            skipped,
            stability: TorusStability::quasi_periodic(),
        })
    }
}
