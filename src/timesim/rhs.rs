//! The first-order right-hand side `y = (q, q̇)`, `ẏ = (q̇, M⁻¹(f - D q̇ - K q - Σ w f_e))`.
//!
//! A law with memory is evaluated by its step from the state committed after the last accepted
//! step, without committing (the state is frozen over a step; see [`super::memory`]).

use crate::error::{Error, Result};
use crate::force::MAX_STATE;
use crate::model::Model;
use differential_equations::prelude::*;
use nalgebra::{Cholesky, DVector, Dyn};
use std::cell::{Cell, RefCell};

pub(super) struct Rhs<'m> {
    model: &'m Model,
    chol: Cholesky<f64, Dyn>,
    omega: f64,
    /// (t_a, θ_a, θ_lo, θ_hi) of the current segment.
    segment: Cell<(f64, f64, f64, f64)>,
    acc: RefCell<DVector<f64>>,
    /// The committed state of every element with memory (unused entries for the others).
    pub(super) states: RefCell<Vec<[f64; MAX_STATE]>>,
    /// `true` if an element has memory.
    memory: bool,
}

impl<'m> Rhs<'m> {
    pub(super) fn new(model: &'m Model, omega: f64) -> Result<Self> {
        let chol = model
            .dense("time integration")?
            .mass
            .cholesky()
            .ok_or_else(|| Error::MassNotPositiveDefinite {
                reason: "Cholesky factorisation failed".into(),
            })?;
        let states = model
            .elements()
            .iter()
            .map(|e| {
                let mut s = [0.0; MAX_STATE];
                if let Some(m) = e.law().memory() {
                    m.initial_state(&mut s[..m.state_len()]);
                }
                s
            })
            .collect();
        Ok(Self {
            model,
            states: RefCell::new(states),
            memory: model.memory_element().is_some(),
            chol,
            omega,
            segment: Cell::new((0.0, 0.0, 0.0, std::f64::consts::TAU)),
            acc: RefCell::new(DVector::zeros(model.n_dofs())),
        })
    }

    /// The model.
    pub(super) fn model(&self) -> &'m Model {
        self.model
    }

    /// `true` if an element's law has memory.
    pub(super) fn has_memory(&self) -> bool {
        self.memory
    }

    /// The angle θ the laws see at time `t` (clamped inside the current segment).
    pub(super) fn theta(&self, t: f64) -> f64 {
        let (ta, tha, lo, hi) = self.segment.get();
        (tha + self.omega * (t - ta)).clamp(lo, hi)
    }

    /// The next calls see angles `θ = θ_a + Ω (t - t_a)` clamped inside `[θ_a, θ_b]`, so the
    /// laws take their values from inside the segment even at its ends.
    pub(super) fn enter_segment(&self, t_a: f64, theta_a: f64, theta_b: f64) {
        let delta = 1e-9 * (theta_b - theta_a);
        self.segment
            .set((t_a, theta_a, theta_a + delta, theta_b - delta));
    }
}

impl ODE<f64, Vec<f64>> for Rhs<'_> {
    fn diff(&self, t: f64, y: &Vec<f64>, dydt: &mut Vec<f64>) {
        let n = self.model.n_dofs();
        let (q, v) = y.split_at(n);
        let theta = self.theta(t);
        let states = self.states.borrow();
        let mut a = self.acc.borrow_mut();
        a.fill(0.0);
        self.model.load_into(self.omega, theta, a.as_mut_slice());
        let a_slice = a.as_mut_slice();
        self.model.structural_damping().mul_add(-1.0, v, a_slice);
        self.model.structural_stiffness().mul_add(-1.0, q, a_slice);
        for (e, s) in self.model.elements().iter().zip(states.iter()) {
            let (u, du) = (e.gather(q), e.gather(v));
            let f = match e.law().memory() {
                None => e.law().force(theta, u, du),
                Some(m) => {
                    let mut frozen = *s;
                    m.step(theta, u, du, &mut frozen[..m.state_len()])
                }
            };
            e.scatter_add(-f, a.as_mut_slice());
        }
        self.chol.solve_mut(&mut *a);
        dydt[..n].copy_from_slice(v);
        dydt[n..].copy_from_slice(a.as_slice());
    }
}

/// Keeps only the point at the end of the interval.
pub(super) struct LastPoint {
    t_end: f64,
}

impl LastPoint {
    pub(super) fn new(t_end: f64) -> Self {
        Self { t_end }
    }
}

impl Solout<f64, Vec<f64>> for LastPoint {
    fn solout<I>(
        &mut self,
        t_curr: f64,
        _t_prev: f64,
        y_curr: &Vec<f64>,
        _y_prev: &Vec<f64>,
        _interpolator: &mut I,
        solution: &mut Solution<f64, Vec<f64>>,
    ) -> ControlFlag<f64, Vec<f64>>
    where
        I: Interpolation<f64, Vec<f64>> + ?Sized,
    {
        if t_curr >= self.t_end - 1e-12 * self.t_end.abs().max(1.0) {
            solution.push(t_curr, y_curr.clone());
        }
        ControlFlag::Continue
    }
}
