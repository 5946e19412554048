//! The period map of the time-domain model with the states of its laws with memory, for the
//! Floquet analysis of such laws ([`crate::stability`]): `x = (q, q̇, s) ↦ x(νT)`, `s` the
//! states of every element with memory in element order, integrated as the time-domain
//! reference does (DOP853, restarted at every time jump of a law, the law states committed
//! after every step).

use super::rhs::Rhs;
use super::scale::state_scale;
use super::{segment_bounds, TimeSimulation};
use crate::error::{Error, Result};
use crate::model::Model;
use std::f64::consts::TAU;

/// `x ↦ φ_{νT}(x)` of a model at one speed.
pub(crate) struct PeriodMap<'m> {
    sim: TimeSimulation,
    rhs: Rhs<'m>,
    bounds: Vec<f64>,
    period: f64,
    periods: usize,
    atol: Vec<f64>,
    /// `(element, state length)` of every element with memory.
    laws: Vec<(usize, usize)>,
}

impl<'m> PeriodMap<'m> {
    /// The map over `periods` forcing periods `2π/Ω` of `model`, integrated to `rtol`.
    pub(crate) fn new(model: &'m Model, omega: f64, periods: usize, rtol: f64) -> Result<Self> {
        let sim = TimeSimulation {
            rtol,
            ..TimeSimulation::default()
        };
        sim.validate()?;
        let atol = state_scale(model, omega)
            .iter()
            .map(|s| 1e-3 * rtol * s)
            .collect();
        let laws = model
            .elements()
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.law().memory().map(|m| (i, m.state_len())))
            .collect();
        Ok(Self {
            sim,
            rhs: Rhs::new(model, omega)?,
            bounds: segment_bounds(model),
            period: TAU / omega,
            periods: periods.max(1),
            atol,
            laws,
        })
    }

    /// Numbers in the laws' states.
    pub(crate) fn state_len(&self) -> usize {
        self.laws.iter().map(|(_, l)| l).sum()
    }

    /// `(element, state length)` of every element with memory, in the order of `s`.
    pub(crate) fn laws(&self) -> &[(usize, usize)] {
        &self.laws
    }

    /// `x(νT)` from `x(0) = x` (length `2n +` [`PeriodMap::state_len`]) and the integrator's
    /// steps.
    pub(crate) fn apply(&self, x: &[f64]) -> Result<(Vec<f64>, usize)> {
        let n2 = 2 * self.rhs.model().n_dofs();
        if x.len() != n2 + self.state_len() {
            return Err(Error::DimensionMismatch {
                context: "period map".into(),
                expected: format!("{} numbers", n2 + self.state_len()),
                got: format!("{}", x.len()),
            });
        }
        {
            let mut states = self.rhs.states.borrow_mut();
            let mut at = n2;
            for &(e, len) in &self.laws {
                states[e][..len].copy_from_slice(&x[at..at + len]);
                at += len;
            }
        }
        let mut y = x[..n2].to_vec();
        let (mut steps, mut evals) = (0, 0);
        for p in 0..self.periods {
            self.sim.integrate_period(
                &self.rhs,
                &self.bounds,
                p,
                self.period,
                &self.atol,
                &mut y,
                None,
                &mut steps,
                &mut evals,
            )?;
        }
        let states = self.rhs.states.borrow();
        for &(e, len) in &self.laws {
            y.extend_from_slice(&states[e][..len]);
        }
        Ok((y, steps))
    }
}
