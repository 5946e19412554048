//! The flow of the shooting over `ν` periods: exact exponentials, which integrate the state
//! alone and multiply the monodromy matrix of a pass only when asked
//! ([`record`](super::record)), or Runge–Kutta, which integrates the variational equation with
//! the state (its monodromy matrix comes with every pass).

use super::exp_flow::ExpFlow;
use super::record::Step;
use crate::error::{Error, Result};
use crate::stability::integrated::dopri::Stepper;
use crate::stability::integrated::flow::{Flow, FlowOptions};
use nalgebra::DMatrix;

/// The flow over a period: exponentials or Runge–Kutta.
pub(crate) enum Integration<'c, 'm> {
    RungeKutta {
        flow: Flow<'c, 'm>,
        stepper: Stepper,
        opts: FlowOptions,
        /// `(q, q̇, Φ̃)` at the end of the last pass.
        y: Vec<f64>,
        /// The state's size `2n`.
        states: usize,
    },
    Exponential {
        flow: ExpFlow<'c, 'm>,
        /// The pieces of the last pass.
        record: Vec<Step>,
    },
}

impl<'c, 'm> Integration<'c, 'm> {
    /// The Runge–Kutta flow.
    pub(crate) fn runge_kutta(flow: Flow<'c, 'm>, opts: FlowOptions, states: usize) -> Self {
        Integration::RungeKutta {
            flow,
            stepper: Stepper::new(states * (1 + states)),
            opts,
            y: vec![0.0; states * (1 + states)],
            states,
        }
    }

    /// The exponential flow.
    pub(crate) fn exponential(flow: ExpFlow<'c, 'm>) -> Self {
        Integration::Exponential {
            flow,
            record: Vec::new(),
        }
    }

    /// `x = (q, q̇)` after `periods` periods from `x`. `Ok(false)` if the exponential flow met a
    /// law that is not affine on its piece (`x` is then meaningless).
    pub(crate) fn pass(&mut self, x: &mut [f64], periods: usize) -> Result<bool> {
        let s2 = x.len();
        match self {
            Integration::RungeKutta {
                flow,
                stepper,
                opts,
                y,
                ..
            } => {
                y[..s2].copy_from_slice(x);
                y[s2..].fill(0.0);
                for i in 0..s2 {
                    y[s2 + i * s2 + i] = 1.0;
                }
                for _ in 0..periods {
                    flow.period(y, opts, stepper)?;
                }
                if y[s2..].iter().any(|v| !v.is_finite()) {
                    return Err(Error::NonFinite {
                        what: "monodromy matrix".into(),
                    });
                }
                x.copy_from_slice(&y[..s2]);
                Ok(true)
            }
            Integration::Exponential { flow, record } => {
                record.clear();
                flow.begin_pass();
                for _ in 0..periods {
                    if !flow.orbit(x, record)? {
                        return Ok(false);
                    }
                }
                flow.end_pass();
                Ok(true)
            }
        }
    }

    /// The scaled monodromy matrix `Φ̃` of the last pass if it comes without cost (Runge–Kutta).
    pub(crate) fn free_monodromy(&self) -> Option<DMatrix<f64>> {
        match self {
            &Integration::RungeKutta { ref y, states, .. } => {
                Some(DMatrix::from_column_slice(states, states, &y[states..]))
            }
            Integration::Exponential { .. } => None,
        }
    }

    /// The scaled monodromy matrix `Φ̃` of the last pass.
    pub(crate) fn monodromy(&mut self) -> Result<DMatrix<f64>> {
        match self {
            Integration::RungeKutta { .. } => Ok(self.free_monodromy().expect("Runge–Kutta")),
            Integration::Exponential { flow, record } => flow.monodromy(record),
        }
    }

    /// The exponential flow's generators, for the next analysis (none from Runge–Kutta).
    pub(crate) fn kept_generators(&mut self) -> super::kept::KeptGenerators {
        match self {
            Integration::Exponential { flow, .. } => flow.kept(),
            Integration::RungeKutta { .. } => Default::default(),
        }
    }

    /// Integration steps so far.
    pub(crate) fn steps(&self) -> usize {
        match self {
            Integration::RungeKutta { flow, .. } => flow.steps,
            Integration::Exponential { flow, .. } => flow.steps,
        }
    }
}
