//! The pieces' generators of the exponential flow ([`exponential`](super::exp_flow)) and
//! what is kept per generator: the scaled load as an oscillator ([`Forcing`]), and per
//! distinct generator ([`State`]) the Taylor powers and the exact sub-step `(E_δ₀, X_δ₀)`; the
//! monodromy matrix's factors per generator are the [`propagator`](super::propagator)'s.
//!
//! **Forcing.** With the oscillator state `z = (1, cos k₁Ωt, sin k₁Ωt, …)` over the load
//! orders, `z' = S z`, and `C` its map to the loads summed per loaded DOF, the scaled load is
//! `b̃(t) = [0; G C z(t)]`, `G = M⁻¹ Vᵀ[e_l …] / s_v`; the piece adds the constant
//! `[0; -Σ f0_e M⁻¹ w_e / s_v]` on the state `z₀ = 1`. Its `i`-th time derivative is
//! `[0; G C Sⁱ z]`.
//!
//! **Sub-step.** Over `δ` from `(x̃, z)` the exact solution is `x̃ ← E_δ x̃ + X_δ z` with
//! `E_δ = e^{Ãδ}` and `X_δ = ∫₀^δ e^{Ã(δ-s)} B e^{Ss} ds = Σ_{j>=0} δ^{j+1} φ_{j+1}(Ãδ) B Sʲ`
//! (`B` the forcing matrix), cut at the first `p` with `(kΩδ)^{p+1}/(p+1)! < 1e-16`. Both are
//! formed at `δ₀/2^f` with `‖Ã δ₀/2^f‖₁ <= 1` and doubled `f` times:
//! `E_{2δ} = E_δ²`, `X_{2δ} = E_δ X_δ + X_δ e^{Sδ}` (two sub-steps in a row).

use super::expm::{inverse_factorial, phi_narrow, squarings, ExpWork, Powers};
use super::kernels::{gemv_sum, product};
use crate::stability::system::Coordinates;
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// Highest power of `Sδ` in the forcing's series.
const MAX_DEGREE: usize = 8;

/// The load as an oscillator.
pub(crate) struct Forcing {
    omega: f64,
    /// The load orders (0 first: the constant state).
    orders: Vec<usize>,
    /// `G` (n × loaded DOFs).
    dirs: DMatrix<f64>,
    /// `C Sʲ`, `j = 0..=MAX_DEGREE`.
    channels: Vec<DMatrix<f64>>,
    /// `G C` (n × oscillator states): the load on the rates; the positions get none.
    load: DMatrix<f64>,
    /// `S`.
    generator: DMatrix<f64>,
}

impl Forcing {
    pub(crate) fn new(sys: &Coordinates, m_inv: &DMatrix<f64>, scale_v: f64, omega: f64) -> Self {
        let model = sys.model;
        let n = sys.len();
        let mut orders: Vec<usize> = model.loads().iter().map(|l| l.order).collect();
        orders.push(0);
        orders.sort_unstable();
        orders.dedup();
        let states = 2 * orders.len() - 1;
        let dofs = model.loaded_dofs();
        let mut dirs = DMatrix::zeros(n, dofs.len());
        let mut c = DMatrix::zeros(dofs.len(), states);
        for (l, dir) in model.loads().iter().zip(&sys.loads) {
            let d = dofs.binary_search(&l.dof).unwrap_or(0);
            let mut col = DVector::zeros(n);
            for &(i, w) in dir {
                col[i] += w;
            }
            dirs.set_column(d, &(m_inv * col / scale_v));
            let (lc, ls) = l.at(omega);
            match orders.iter().position(|&o| o == l.order) {
                Some(i) if i > 0 => {
                    c[(d, 2 * i - 1)] += lc;
                    c[(d, 2 * i)] += ls;
                }
                _ => c[(d, 0)] += lc,
            }
        }
        let mut generator = DMatrix::zeros(states, states);
        for (i, &k) in orders.iter().enumerate().skip(1) {
            let w = k as f64 * omega;
            generator[(2 * i - 1, 2 * i)] = -w;
            generator[(2 * i, 2 * i - 1)] = w;
        }
        let mut channels = vec![c];
        for j in 1..=MAX_DEGREE {
            let next = &channels[j - 1] * &generator;
            channels.push(next);
        }
        let load = &dirs * &channels[0];
        Self {
            omega,
            orders,
            dirs,
            channels,
            load,
            generator,
        }
    }

    /// Number of oscillator states.
    pub(crate) fn states(&self) -> usize {
        self.generator.nrows()
    }

    /// The fastest load frequency.
    pub(crate) fn top(&self) -> f64 {
        self.orders.last().copied().unwrap_or(0) as f64 * self.omega
    }

    /// `z(t)`.
    pub(crate) fn oscillator(&self, t: f64, z: &mut DVector<f64>) {
        let (s1, c1) = (self.omega * t).sin_cos();
        z[0] = 1.0;
        let (mut c, mut s, mut k) = (1.0, 0.0, 0);
        for (i, &order) in self.orders.iter().enumerate().skip(1) {
            while k < order {
                (c, s) = (c * c1 - s * s1, s * c1 + c * s1);
                k += 1;
            }
            z[2 * i - 1] = c;
            z[2 * i] = s;
        }
    }

    /// `x ← x e^{Sδ}`, block by block.
    fn rotate(&self, x: &mut DMatrix<f64>, delta: f64) {
        for (i, &k) in self.orders.iter().enumerate().skip(1) {
            let (s, c) = (k as f64 * self.omega * delta).sin_cos();
            for r in 0..x.nrows() {
                let (a, b) = (x[(r, 2 * i - 1)], x[(r, 2 * i)]);
                x[(r, 2 * i - 1)] = a * c + b * s;
                x[(r, 2 * i)] = -a * s + b * c;
            }
        }
    }

    /// `z ← e^{Sδ} z` (each pair turned by `kΩδ`; `turns` from [`Forcing::turns`]).
    pub(crate) fn advance(&self, turns: &[(f64, f64)], z: &mut DVector<f64>) {
        for (b, &(s, c)) in turns.iter().enumerate().skip(1) {
            let (x, y) = (z[2 * b - 1], z[2 * b]);
            z[2 * b - 1] = c * x - s * y;
            z[2 * b] = s * x + c * y;
        }
    }

    /// `(sin kΩδ, cos kΩδ)` per order (the constant state first).
    pub(crate) fn turns(&self, delta: f64) -> Vec<(f64, f64)> {
        self.orders
            .iter()
            .map(|&k| (k as f64 * self.omega * delta).sin_cos())
            .collect()
    }

    /// `G C`: the scaled load is `[0; G C] z` (`Sⁱ z` for its `i`-th time derivative).
    pub(crate) fn load(&self) -> &DMatrix<f64> {
        &self.load
    }

    /// `w ← S w` (each pair `(c, s)` of order `k` becomes `kΩ (-s, c)`, the constant 0).
    pub(crate) fn differentiate(&self, w: &mut DVector<f64>) {
        w[0] = 0.0;
        for (b, &k) in self.orders.iter().enumerate().skip(1) {
            let f = k as f64 * self.omega;
            let (x, y) = (w[2 * b - 1], w[2 * b]);
            w[2 * b - 1] = -f * y;
            w[2 * b] = f * x;
        }
    }
}

/// What both the orbit and its monodromy matrix need of one generator `Ã`: its powers and the
/// exact sub-step `E_δ₀` (shared with the monodromy side, which may run on another thread),
/// and the sub-steps `E_δ` of the doubling `δ = δ₀/2^f, …, δ₀/2` that forms the load's part
/// `X_δ₀` of every point. A sweep's points keep it ([`KeptGenerators`](super::kept::KeptGenerators)):
/// it depends on `Ã`, `δ₀` and `f` alone, not on the speed.
pub(crate) struct Core {
    pub(crate) powers: Powers,
    /// `E_δ₀`.
    pub(crate) e0: DMatrix<f64>,
    /// `E_δ` for `δ = δ₀/2^f, …, δ₀/2` (`f` entries, the finest first).
    pub(crate) levels: Vec<DMatrix<f64>>,
    /// The rates' rows of `Ã` (`n × 2n`); its positions' rows are `[0, ω_s I]`.
    lower: DMatrix<f64>,
    /// `ω_s = s_v/s_q`.
    omega_s: f64,
    /// `δ₀` and the halvings `f`.
    delta0: f64,
    fine: u32,
}

impl Core {
    /// The core of `a` with sub-step `delta0`, `E_δ₀` formed at `δ₀/2^fine` by the Taylor
    /// polynomial and squared `fine` times.
    pub(crate) fn new(a: DMatrix<f64>, delta0: f64, fine: u32, work: &mut ExpWork) -> Self {
        let n = a.nrows() / 2;
        let lower = a.rows(n, n).into_owned();
        let omega_s = if n > 0 { a[(0, n)] } else { 0.0 };
        let powers = Powers::new(a);
        let m = powers.a.nrows();
        let mut e = DMatrix::zeros(m, m);
        work.taylor(&powers, delta0 / f64::powi(2.0, fine as i32), &mut e);
        let mut levels = Vec::with_capacity(fine as usize);
        let mut squared = e.clone();
        for _ in 0..fine {
            product(&e, &e, &mut squared);
            levels.push(std::mem::replace(&mut e, squared.clone()));
        }
        Self {
            powers,
            e0: e,
            levels,
            lower,
            omega_s,
            delta0,
            fine,
        }
    }

    /// `true` if this is the core of `a` with sub-step `delta0` and `fine` halvings, to the
    /// bit.
    pub(crate) fn is(&self, a: &DMatrix<f64>, delta0: f64, fine: u32) -> bool {
        self.delta0.to_bits() == delta0.to_bits()
            && self.fine == fine
            && self.powers.a.shape() == a.shape()
            && self
                .powers
                .a
                .iter()
                .zip(a.iter())
                .all(|(x, y)| x.to_bits() == y.to_bits())
    }

    /// The halvings `f` of `δ₀` at which both the Taylor polynomial of `e^{Ãδ}` (`‖Ã‖₁ δ <=
    /// 1`) and the forcing's series (a degree up to 8) converge, and that degree.
    pub(crate) fn fine(norm: f64, forcing: &Forcing, delta0: f64) -> (u32, usize) {
        let mut fine = squarings(norm * delta0);
        loop {
            let x = forcing.top() * delta0 / f64::powi(2.0, fine as i32);
            match (1..=MAX_DEGREE)
                .find(|&p| x.powi(p as i32 + 1) * inverse_factorial(p + 1) < 1e-16)
            {
                Some(p) => return (fine, p),
                None => fine += 1,
            }
        }
    }
}

/// What the orbit keeps of one generator `Ã`.
pub(crate) struct State {
    pub(crate) core: Arc<Core>,
    /// `X_δ₀`.
    pub(crate) x0: DMatrix<f64>,
    /// The constant part of the forcing (velocity rows).
    pub(crate) offset: DVector<f64>,
}

impl State {
    /// The state of the generator `core` (its `f` halvings from [`Core::fine`], with `degree`)
    /// with the forcing `forcing` plus `offset`, sub-step `delta0`.
    pub(crate) fn new(
        core: Arc<Core>,
        degree: usize,
        offset: DVector<f64>,
        forcing: &Forcing,
        delta0: f64,
    ) -> Self {
        let powers = &core.powers;
        let m = powers.a.nrows();
        let n = m / 2;
        let loads = forcing.dirs.ncols();
        let fine = core.levels.len();
        let mut delta = delta0 / f64::powi(2.0, fine as i32);
        // φ_{j+1}(Ãδ) [0; G | offset], then X_δ = Σ_j δ^{j+1} φ_{j+1} [0; G] C Sʲ + δ φ₁ offset e₀ᵀ.
        let mut v = DMatrix::zeros(m, loads + 1);
        v.view_mut((n, 0), (n, loads)).copy_from(&forcing.dirs);
        v.set_column(loads, &offset);
        let z = &powers.a * delta;
        let mut psi = vec![DMatrix::zeros(m, loads + 1); degree + 1];
        let mut tmp = DMatrix::zeros(m, loads + 1);
        phi_narrow(&z, &v, &mut psi, &mut tmp);
        let mut x = DMatrix::zeros(m, forcing.states());
        let mut power = delta;
        for (j, p) in psi.iter().enumerate() {
            x.gemm(power, &p.columns(0, loads), &forcing.channels[j], 1.0);
            power *= delta;
        }
        for i in 0..m {
            x[(i, 0)] += delta * psi[0][(i, loads)];
        }
        // X_{2δ} = E_δ X_δ + X_δ e^{Sδ} (two sub-steps in a row).
        let mut doubled = x.clone();
        for e in &core.levels {
            product(e, &x, &mut doubled);
            forcing.rotate(&mut x, delta);
            doubled += &x;
            std::mem::swap(&mut x, &mut doubled);
            delta *= 2.0;
        }
        Self {
            core,
            x0: x,
            offset,
        }
    }

    /// The state of `core` for the monodromy matrix alone (an orbit that is not integrated,
    /// [`Orbit::Harmonic`](crate::stability::Orbit::Harmonic)): without the load's part `X_δ₀`.
    pub(crate) fn without_load(core: Arc<Core>, offset: DVector<f64>) -> Self {
        Self {
            core,
            x0: DMatrix::zeros(0, 0),
            offset,
        }
    }

    /// `E_δ₀`.
    pub(crate) fn e0(&self) -> &DMatrix<f64> {
        &self.core.e0
    }
}

/// The Taylor series of the exact solution of a piece through a state:
/// `x̃(t+τ) = Σ τⁱ x̃⁽ⁱ⁾/i!`, `x̃⁽ⁱ⁺¹⁾ = Ã x̃⁽ⁱ⁾ + b̃⁽ⁱ⁾(t)` (`b̃⁽ⁱ⁾` the load's derivatives
/// and, for `i = 0`, the piece's constant).
#[derive(Default)]
pub(crate) struct Expansion {
    derivs: Vec<DVector<f64>>,
    /// The oscillator's `Sⁱ z` (a buffer).
    z: DVector<f64>,
    terms: usize,
}

impl Expansion {
    /// The coefficients at `t` through `x̃` on the piece `state`, until their terms over
    /// `horizon` are below 1e-18 of the state.
    pub(crate) fn expand(
        &mut self,
        state: &State,
        forcing: &Forcing,
        x: &DVector<f64>,
        t: f64,
        horizon: f64,
    ) {
        let m = x.len();
        let n = m / 2;
        let z = &mut self.z;
        if z.len() != forcing.states() {
            *z = DVector::zeros(forcing.states());
        }
        forcing.oscillator(t, z);
        if self.derivs.is_empty() {
            self.derivs.push(DVector::zeros(m));
        }
        self.derivs[0].copy_from(x);
        let size = x.amax().max(f64::MIN_POSITIVE);
        let mut factor = 1.0;
        self.terms = 1;
        for i in 0..100 {
            if self.derivs.len() == i + 1 {
                self.derivs.push(DVector::zeros(m));
            }
            let (done, next) = self.derivs.split_at_mut(i + 1);
            let next = &mut next[0];
            // x̃⁽ⁱ⁺¹⁾ = Ã x̃⁽ⁱ⁾ + [0; G C] Sⁱ z: the positions' rows are ω_s times the rates
            // (the same bits as the whole product), the rates' rows a product.
            let core = &state.core;
            let (top, v) = next.as_mut_slice().split_at_mut(n);
            for (t, r) in top.iter_mut().zip(&done[i].as_slice()[n..]) {
                *t = core.omega_s * r;
            }
            let terms = [
                (&core.lower, done[i].as_slice()),
                (forcing.load(), z.as_slice()),
            ];
            gemv_sum(&terms, v, false);
            forcing.differentiate(z);
            if i == 0 {
                for (o, c) in v.iter_mut().zip(&state.offset.as_slice()[n..]) {
                    *o += c;
                }
            }
            factor *= horizon / (i + 1) as f64;
            self.terms = i + 2;
            if i > 4 && next.amax() * factor <= 1e-18 * size {
                break;
            }
        }
    }

    /// The expanded solution at `τ` after the expansion point.
    pub(crate) fn evaluate(&self, tau: f64, out: &mut DVector<f64>) {
        out.copy_from(&self.derivs[0]);
        let mut c = 1.0;
        for (i, d) in self.derivs[1..self.terms].iter().enumerate() {
            c *= tau / (i + 1) as f64;
            out.axpy(c, d, 1.0);
        }
    }
}
