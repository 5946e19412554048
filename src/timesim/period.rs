//! One period of the time integration, segment by segment between the time jumps the laws
//! declare, optionally sampled at N equidistant angles.

use super::memory;
use super::rhs::{LastPoint, Rhs};
use super::TimeSimulation;
use crate::error::{Error, Result};
use crate::model::Model;
use differential_equations::prelude::*;
use std::f64::consts::TAU;

impl TimeSimulation {
    /// Integrates period `p` segment by segment; optionally samples q at N equidistant angles.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn integrate_period(
        &self,
        rhs: &Rhs,
        bounds: &[f64],
        p: usize,
        period: f64,
        atol: &[f64],
        y: &mut Vec<f64>,
        mut samples: Option<&mut Vec<Vec<f64>>>,
        steps: &mut usize,
        evals: &mut usize,
    ) -> Result<()> {
        let n = y.len() / 2;
        let t_period = p as f64 * period;
        let omega = TAU / period;
        for w in bounds.windows(2) {
            let (ta, tb) = (t_period + w[0] / omega, t_period + w[1] / omega);
            rhs.enter_segment(ta, w[0], w[1]);
            let mut method = ExplicitRungeKutta::dop853()
                .rtol(self.rtol)
                .atol(atol.to_vec())
                .max_steps(usize::MAX / 4);
            if let Some(h) = self.max_step {
                method = method.h_max(h * period);
            }
            let y0 = y.clone();
            let (t_end, y_end) = if rhs.has_memory() {
                memory::integrate_segment(
                    rhs,
                    (self.rtol, atol, self.max_step.map(|h| h * period)),
                    (ta, tb),
                    (w[0], w[1], t_period, omega),
                    y0,
                    samples.as_deref_mut(),
                    steps,
                    evals,
                )?
            } else {
                match samples.as_deref_mut() {
                    None => {
                        let sol = IVP::ode(rhs, ta, tb, y0)
                            .method(method)
                            .solout(LastPoint::new(tb))
                            .solve()
                            .map_err(|e| Error::TimeIntegration {
                                reason: format!("{e:?}"),
                            })?;
                        *steps += sol.steps.accepted + sol.steps.rejected;
                        *evals += sol.evals.function;
                        let (t, y) = sol.last().map_err(|e| Error::TimeIntegration {
                            reason: e.to_string(),
                        })?;
                        (*t, y.clone())
                    }
                    Some(out) => {
                        let ns = out[0].len();
                        let js: Vec<usize> = (0..ns)
                            .filter(|&j| {
                                let th = TAU * j as f64 / ns as f64;
                                th >= w[0] && th < w[1]
                            })
                            .collect();
                        let mut ts: Vec<f64> = js
                            .iter()
                            .map(|&j| t_period + TAU * j as f64 / ns as f64 / omega)
                            .collect();
                        ts.push(tb);
                        let sol = IVP::ode(rhs, ta, tb, y0)
                            .method(method)
                            .t_eval(&ts)
                            .solve()
                            .map_err(|e| Error::TimeIntegration {
                                reason: format!("{e:?}"),
                            })?;
                        for (&j, yj) in js.iter().zip(&sol.y) {
                            for (i, row) in out.iter_mut().enumerate() {
                                row[j] = yj[i];
                            }
                        }
                        let (t, y) = sol.last().map_err(|e| Error::TimeIntegration {
                            reason: e.to_string(),
                        })?;
                        (*t, y.clone())
                    }
                }
            };
            if (t_end - tb).abs() > 1e-9 * period {
                return Err(Error::TimeIntegration {
                    reason: format!("stopped at t = {t_end} before the segment end {tb}"),
                });
            }
            *y = y_end;
            debug_assert_eq!(y.len(), 2 * n);
        }
        Ok(())
    }
}

/// Segment bounds in θ over one period: 0, every declared time jump, 2π.
pub(crate) fn segment_bounds(model: &Model) -> Vec<f64> {
    let mut b: Vec<f64> = model
        .elements()
        .iter()
        .flat_map(|e| e.law().time_breakpoints())
        .filter(|t| *t > 1e-12 && *t < TAU - 1e-12)
        .collect();
    b.push(0.0);
    b.push(TAU);
    b.sort_by(f64::total_cmp);
    b.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    b
}
