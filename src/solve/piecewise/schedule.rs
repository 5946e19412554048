//! The pieces of a period between the coefficients' jumps, and the constant system on each.

pub(super) use super::admission::check;
use super::admission::checked;
use super::factor::ComplexLu;
use super::free_body::FreeBody;
use super::phasors::EdgePhasors;
use crate::error::{Error, Result};
use crate::model::Model;
use crate::stability::expm::Powers;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Angles closer than this (rad) are one breakpoint.
const SAME_ANGLE: f64 = 1e-12;

/// A piece `start <= θ < end` of the period with one configuration of coefficients.
pub(super) struct Piece {
    pub(super) start: f64,
    pub(super) end: f64,
    pub(super) configuration: usize,
}

impl Piece {
    /// Its duration `(end - start) / Ω` in seconds.
    pub(super) fn duration(&self, omega: f64) -> f64 {
        (self.end - self.start) / omega
    }
}

/// The constant system of one set of coefficients: `M q̈ + D q̇ + K q = f(θ)`.
pub(super) struct Configuration {
    pub(super) stiffness: DMatrix<f64>,
    pub(super) damping: DMatrix<f64>,
    /// `A = [0 ω_s I; -M⁻¹K/ω_s -M⁻¹D]` in the scaled state `(q, q̇/ω_s)`, with its powers.
    pub(super) generator: Powers,
    /// The steady state under the loads, `Q_k` for orders `k = 0..=K` (one-sided, `Q[k n + i]`).
    steady: Vec<Complex64>,
    /// `M⁻¹K`, `M⁻¹D`: the free motion's accelerations.
    pub(super) mass_stiffness: DMatrix<f64>,
    pub(super) mass_damping: DMatrix<f64>,
    /// Every element's `(k_e, d_e, f_e)` on this configuration (force `k_e u + d_e u̇ + f_e`).
    pub(super) elements: Vec<(f64, f64, f64)>,
    n: usize,
}

/// A configuration's elements' `(k_e, d_e, f_e(θ, 0, 0))` (the last the force at rest of a
/// law with a static offset, a preloaded spring), with its `K`, `D`.
type System = (Vec<(f64, f64, f64)>, DMatrix<f64>, DMatrix<f64>);

/// The pieces of the period and their configurations.
pub(super) struct Schedule {
    pub(super) n: usize,
    pub(super) omega: f64,
    pub(super) mass: DMatrix<f64>,
    /// `ω_s`, the velocity scale of the generators' state.
    velocity_scale: f64,
    pub(super) configurations: Vec<Configuration>,
    pub(super) pieces: Vec<Piece>,
    /// The highest load order K.
    pub(super) model_load_orders: usize,
    /// The rigid-body modes of a model that floats free, separated exactly.
    free_body: Option<FreeBody>,
}

impl Schedule {
    /// Checks that the model is linear with piecewise-constant coefficients, cuts the period
    /// at every element's time breakpoint and builds each distinct configuration.
    pub(super) fn new(model: &Model, omega: f64) -> Result<Self> {
        let n = model.n_dofs();
        let (dense, free_body) = checked(model, Some(omega))?;
        let mut breaks: Vec<f64> = model
            .elements()
            .iter()
            .flat_map(|e| e.law().time_breakpoints())
            .map(|t| t.rem_euclid(TAU))
            .collect();
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| (*a - *b).abs() < SAME_ANGLE);
        if breaks.len() > 1 && breaks[0] + TAU - breaks[breaks.len() - 1] < SAME_ANGLE {
            breaks.pop();
        }
        if breaks.is_empty() {
            breaks.push(0.0);
        }
        let mut schedule = Self {
            n,
            omega,
            mass: dense.mass.clone(),
            velocity_scale: 1.0,
            configurations: Vec::new(),
            pieces: Vec::new(),
            model_load_orders: model.max_load_order(),
            free_body,
        };
        let mut systems: Vec<System> = Vec::new();
        for (i, &start) in breaks.iter().enumerate() {
            let end = breaks.get(i + 1).copied().unwrap_or(breaks[0] + TAU);
            let middle = 0.5 * (start + end);
            let coefficients: Vec<(f64, f64, f64)> = model
                .elements()
                .iter()
                .map(|e| {
                    let (k, d) = e.law().derivatives(middle, 0.0, 0.0);
                    (k, d, e.law().force(middle, 0.0, 0.0))
                })
                .collect();
            let configuration = match systems.iter().position(|s| s.0 == coefficients) {
                Some(c) => c,
                None => {
                    let (mut k, mut d) = (dense.stiffness.clone(), dense.damping.clone());
                    for (e, &(ke, de, fe)) in model.elements().iter().zip(&coefficients) {
                        if !(ke.is_finite() && de.is_finite() && fe.is_finite()) {
                            return Err(Error::NonFinite {
                                what: format!(
                                    "the coefficients of element `{}` at angle {middle}",
                                    e.name()
                                ),
                            });
                        }
                        for &(i, wi) in e.weights() {
                            for &(j, wj) in e.weights() {
                                k[(i, j)] += ke * wi * wj;
                                d[(i, j)] += de * wi * wj;
                            }
                        }
                    }
                    systems.push((coefficients, k, d));
                    systems.len() - 1
                }
            };
            schedule.pieces.push(Piece {
                start,
                end,
                configuration,
            });
        }
        let mass_lu = dense.mass.clone().lu();
        let inverse = mass_lu
            .try_inverse()
            .ok_or_else(|| Error::MassNotPositiveDefinite {
                reason: "singular (the exact piecewise solution needs M⁻¹)".into(),
            })?;
        // ω_s: the largest M⁻¹K diagonal's root, so that q and q̇/ω_s are of one size.
        let scale = systems
            .iter()
            .flat_map(|(_, k, _)| {
                let mk = &inverse * k;
                (0..n).map(move |i| mk[(i, i)].abs()).collect::<Vec<_>>()
            })
            .fold(0.0f64, f64::max)
            .sqrt();
        schedule.velocity_scale = if scale.is_finite() && scale > 0.0 {
            scale
        } else {
            1.0
        };
        if let Some(free) = schedule.free_body.as_mut() {
            free.set_rate(schedule.velocity_scale, TAU / omega);
        }
        for (coefficients, mut k, mut d) in systems {
            if let Some(free) = &schedule.free_body {
                free.shift(&mut k, &mut d);
            }
            let mut config = schedule.configuration(model, &inverse, &coefficients, k, d)?;
            config.elements = coefficients;
            schedule.configurations.push(config);
        }
        Ok(schedule)
    }

    /// The configuration of `k`, `d` with the elements' forces at rest `rest`: its scaled
    /// generator and its steady state (the forces at rest are static loads `-w_e f_e`).
    fn configuration(
        &self,
        model: &Model,
        mass_inverse: &DMatrix<f64>,
        coefficients: &[(f64, f64, f64)],
        k: DMatrix<f64>,
        d: DMatrix<f64>,
    ) -> Result<Configuration> {
        let n = self.n;
        let ws = self.velocity_scale;
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        let mk = mass_inverse * &k;
        let md = mass_inverse * &d;
        for i in 0..n {
            a[(i, n + i)] = ws;
            for j in 0..n {
                a[(n + i, j)] = -mk[(i, j)] / ws;
                a[(n + i, n + j)] = -md[(i, j)];
            }
        }
        let orders = model.max_load_order();
        let mut steady = vec![Complex64::new(0.0, 0.0); (orders + 1) * n];
        let mut lu = ComplexLu::new(n);
        for order in 0..=orders {
            let block = &mut steady[order * n..(order + 1) * n];
            for load in model.loads().iter().filter(|l| l.order == order) {
                let (cos, sin) = load.at(self.omega);
                let sin = if order == 0 { 0.0 } else { sin };
                block[load.dof] += Complex64::new(cos, -sin);
            }
            if order == 0 {
                for (e, &(_, _, f)) in model.elements().iter().zip(coefficients) {
                    for &(i, w) in e.weights() {
                        block[i] -= w * f;
                    }
                }
            }
            if block.iter().all(|c| c.norm() == 0.0) {
                continue;
            }
            let rigid = self
                .free_body
                .as_ref()
                .map(|free| free.split_load(block, order, self.omega));
            let s = Complex64::new(0.0, order as f64 * self.omega);
            factor_at(&mut lu, &self.mass, &k, &d, s, order, self.omega)?;
            lu.solve(block);
            for (b, r) in block.iter_mut().zip(rigid.iter().flatten()) {
                *b += r;
            }
        }
        Ok(Configuration {
            stiffness: k,
            damping: d,
            generator: Powers::new(a),
            steady,
            mass_stiffness: mk,
            mass_damping: md,
            elements: Vec::new(),
            n,
        })
    }

    /// The highest natural frequency in rad/s, estimated as the root of the largest
    /// diagonal entry of `M⁻¹K` over the configurations (1 if there is none).
    pub(super) fn highest_frequency(&self) -> f64 {
        self.velocity_scale
    }

    /// The number of rigid-body modes (0 for a grounded model).
    pub(super) fn rigid_modes(&self) -> usize {
        self.free_body.as_ref().map_or(0, FreeBody::count)
    }

    /// `ω_s`, the velocity scale of the generators' state.
    pub(super) fn velocity_scale(&self) -> f64 {
        self.velocity_scale
    }

    /// `(q, q̇) -> (q, q̇/ω_s)`.
    pub(super) fn scale_state(&self, mut x: DVector<f64>) -> DVector<f64> {
        x.rows_mut(self.n, self.n).unscale_mut(self.velocity_scale);
        x
    }

    /// `(q, q̇/ω_s) -> (q, q̇)`.
    pub(super) fn unscale_state(&self, mut x: DVector<f64>) -> DVector<f64> {
        x.rows_mut(self.n, self.n).scale_mut(self.velocity_scale);
        x
    }
}

/// Factors `Z(s) = K + sD + s²M` into `lu`; an error names the harmonic where it is singular.
pub(super) fn factor_at(
    lu: &mut ComplexLu,
    mass: &DMatrix<f64>,
    k: &DMatrix<f64>,
    d: &DMatrix<f64>,
    s: Complex64,
    harmonic: usize,
    omega: f64,
) -> Result<()> {
    let s2 = s * s;
    let pivot = lu.factor(|i, j| k[(i, j)] + s * d[(i, j)] + s2 * mass[(i, j)]);
    if pivot < crate::solve::lu::SINGULAR_PIVOT {
        return Err(Error::SingularDynamicStiffness {
            harmonic,
            omega: harmonic as f64 * omega,
            relative_pivot: pivot,
            hint: "a piece of the period (between stiffness jumps) has an undamped resonance or a free rigid-body mode there; the exact piecewise solution needs every piece's Z regular: use harmonic balance".into(),
        });
    }
    Ok(())
}

impl Configuration {
    /// The positions of the steady state at `theta`, `Re Σ_k Q_k e^{ikθ}`, into `out` (`n`).
    pub(super) fn steady_positions_into(&self, theta: f64, out: &mut [f64]) {
        out.fill(0.0);
        for (order, block) in self.steady.chunks(self.n).enumerate() {
            let e = Complex64::from_polar(1.0, order as f64 * theta);
            for (o, q) in out.iter_mut().zip(block) {
                *o += (q * e).re;
            }
        }
    }

    /// The steady state `(q, q̇)` at angle `θ`.
    pub(super) fn steady_state(&self, theta: f64, omega: f64) -> DVector<f64> {
        let n = self.n;
        let mut x = DVector::zeros(2 * n);
        for (order, block) in self.steady.chunks(n).enumerate() {
            let e = Complex64::from_polar(1.0, order as f64 * theta);
            let rate = Complex64::new(0.0, order as f64 * omega);
            for (i, q) in block.iter().enumerate() {
                x[i] += (q * e).re;
                x[n + i] += (rate * q * e).re;
            }
        }
        x
    }

    /// `∫ q_s dt` of the steady state over the angles `a..b`:
    /// `Re Σ_k Q_k (e^{ikb} - e^{ika}) / (ikΩ)`, `Q_0 (b - a)/Ω`.
    pub(super) fn steady_integral(&self, a: f64, b: f64, omega: f64) -> DVector<f64> {
        let n = self.n;
        let mut out = DVector::zeros(n);
        for (order, block) in self.steady.chunks(n).enumerate() {
            let factor = if order == 0 {
                Complex64::new((b - a) / omega, 0.0)
            } else {
                let k = order as f64;
                (Complex64::from_polar(1.0, k * b) - Complex64::from_polar(1.0, k * a))
                    / Complex64::new(0.0, k * omega)
            };
            for (o, q) in out.iter_mut().zip(block) {
                *o += (q * factor).re;
            }
        }
        out
    }

    /// The steady state and its first three time derivatives at angle `θ`:
    /// `Re Σ_k (ikΩ)^m Q_k e^{ikθ}`, `m = 0..=3`.
    pub(super) fn steady_jet_into(&self, theta: f64, omega: f64, jet: &mut [DVector<f64>; 4]) {
        let n = self.n;
        for d in jet.iter_mut() {
            d.fill(0.0);
        }
        for (order, block) in self.steady.chunks(n).enumerate() {
            let e = Complex64::from_polar(1.0, order as f64 * theta);
            let rate = Complex64::new(0.0, order as f64 * omega);
            let mut factor = e;
            for d in jet.iter_mut() {
                for (i, q) in block.iter().enumerate() {
                    d[i] += (factor * q).re;
                }
                factor *= rate;
            }
        }
    }

    /// Adds the two-sided coefficient `c_l` of the steady state on a piece (zero elsewhere)
    /// at the order `l` of `edges`, the piece's phasors: `Σ_k c_k W(l - k)`,
    /// `W(j) = (1/2π) ∫_a^b e^{-ijθ} dθ`.
    pub(super) fn add_steady_window(&self, edges: &EdgePhasors, out: &mut [Complex64]) {
        let n = self.n;
        for (order, block) in self.steady.chunks(n).enumerate() {
            let k = order as i64;
            if order == 0 {
                let w = edges.window(0);
                for (o, q) in out.iter_mut().zip(block) {
                    *o += q * w;
                }
            } else {
                let (wp, wm) = (edges.window(k), edges.window(-k));
                for (o, q) in out.iter_mut().zip(block) {
                    *o += 0.5 * (q * wp + q.conj() * wm);
                }
            }
        }
    }

    /// Factors `Z(lΩ)` of this configuration into `lu`.
    pub(super) fn factor_dynamic_stiffness(
        &self,
        mass: &DMatrix<f64>,
        s: Complex64,
        lu: &mut ComplexLu,
        harmonic: usize,
        omega: f64,
    ) -> Result<()> {
        factor_at(lu, mass, &self.stiffness, &self.damping, s, harmonic, omega)
    }
}
