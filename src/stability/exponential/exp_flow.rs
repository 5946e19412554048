//! The flow over one period by exact exponentials, for models whose laws are affine on every
//! piece ([`affine`](super::affine)): rectangular or constant mesh stiffness, backlash and stop
//! contacts, linear springs and dampers.
//!
//! Between two time jumps of the laws and two kink crossings every law is
//! `f_e = f0_e + k_e u + d_e u̇` with constant `(f0_e, k_e, d_e)`, so in the scaled state
//! `x̃ = (q/s_q, q̇/s_v)` (`ω_s = s_v/s_q`) the equations of motion are linear with constant
//! coefficients and a trigonometric forcing,
//!
//! `x̃' = Ã x̃ + b̃(t)`, `Ã = [[0, ω_s I], [-M⁻¹K/ω_s, -M⁻¹D]]`, `K = K_s + Σ k_e w_e w_eᵀ`,
//! `D = D_s + Σ d_e w_e w_eᵀ`, `b̃ = [0; M⁻¹(f(t) - Σ f0_e w_e)/s_v]`,
//!
//! and the scaled monodromy matrix obeys `Φ̃' = Ã Φ̃`: over a piece of length `h` it is
//! multiplied by `e^{Ãh}`, whatever the stiffness (the contact modes at 10⁵ rad/s that cap an
//! explicit step cost nothing here). A period of the drivetrain has about 700 pieces but only
//! about 40 distinct generators `Ã`; each is kept with its exact sub-step over the flow's
//! `δ₀ = 2^{-⌈log₂ ω_f⌉}` (`ω_f δ₀ <= 1`, ω_f the fastest frequency along the orbit or of the
//! load) and the ladder `E_δ₀^{2^j}` ([`generator`](super::generator)). A piece `h = m δ₀ + r` costs:
//!
//! * the orbit: `m` sub-steps `x̃ ← E_δ₀ x̃ + X_δ₀ z(t)` (`z` the load oscillator), then the
//!   remainder `r` by the Taylor series of the exact solution,
//!   `x̃(t+τ) = Σ τⁱ x̃⁽ⁱ⁾/i!`, `x̃⁽ⁱ⁺¹⁾ = Ã x̃⁽ⁱ⁾ + b̃⁽ⁱ⁾(t)`;
//! * a kink crossing is detected on every sub-step from the cubic Hermite interpolant of `u` as
//!   in the Runge–Kutta flow and located by Newton on the same Taylor series;
//! * the monodromy matrix, afterwards and only for the orbits that need it, from the record of
//!   the pass ([`record`](super::record)): one product per set bit of `m`, and `e^{Ãτ}` for the
//!   last part (`τ = r`, or up to the crossing) by the Taylor polynomial, a linear combination
//!   of the kept `Ãⁱ/i!`; at a crossing the saltation matrix of a force jump.
//!
//! The laws' coefficients are read at a fixed point inside each kink interval
//! ([`Pieces::inside`]), so that equal pieces give bit-equal keys. At the end of every piece
//! each law is evaluated again at the orbit: if its derivatives or its offset have changed (a
//! law that is not affine after all), the flow reports it and the analysis falls back on the
//! Runge–Kutta flow.

use super::expm::{norm1, ExpWork};
use super::generator::{Core, Expansion, Forcing, State};
use super::kept::{Cores, KeptGenerators, WordMap};
use super::kernels::gemv_sum;
use super::kinks::Kinked;
use super::pipeline::{Link, Message};
use super::record::{Assembler, Step};
use crate::error::{Error, Result};
use crate::stability::integrated::pieces::Pieces;
use crate::stability::system::Coordinates;
use nalgebra::{DMatrix, DVector};

/// The flow over one period by exponentials.
pub(crate) struct ExpFlow<'c, 'm> {
    pub(crate) sys: &'c Coordinates<'m>,
    pub(crate) n: usize,
    pub(crate) omega: f64,
    pub(crate) bounds: Vec<f64>,
    pub(crate) pieces: Pieces,
    pub(crate) scale_q: f64,
    pub(crate) scale_v: f64,
    /// The sub-step δ₀ (a power of two).
    pub(crate) delta0: f64,
    max_steps: usize,
    /// `Ã` of the structure alone.
    base: DMatrix<f64>,
    /// `M⁻¹ w_e` (unscaled).
    pub(crate) mw: Vec<DVector<f64>>,
    forcing: Forcing,
    /// The oscillator's turn over δ₀.
    turns: Vec<(f64, f64)>,
    work: ExpWork,
    /// The generators met so far, and their index by the laws' coefficients.
    pub(crate) states: Vec<State>,
    /// Their cores, kept from the last analysis or formed here.
    cores: Cores,
    pub(crate) index: WordMap<Vec<u64>, usize>,
    /// The Taylor series of the exact solution from the last expansion point.
    pub(crate) taylor: Expansion,
    /// The elements with kinks.
    pub(crate) kinks: Kinked,
    /// Integration steps (sub-steps and remainders) over all periods.
    pub(crate) steps: usize,
    /// The monodromy side, here or (linked) on another thread.
    pub(crate) assembler: Box<Assembler>,
    pub(crate) link: Option<Box<Link>>,
    /// The orbit is not integrated ([`ExpFlow::along_harmonics`]): the generators' states
    /// leave out the load's part `X_δ₀`.
    pub(crate) monodromy_only: bool,
}

/// A piece: its generator and the laws' coefficients `(f0_e, k_e, d_e)`.
pub(crate) struct Piece {
    pub(crate) state: usize,
    pub(crate) coefficients: Vec<(f64, f64, f64)>,
}

impl<'c, 'm> ExpFlow<'c, 'm> {
    /// The flow in `sys` at fundamental `omega`, with state scales `s_q`, `s_v` and the fastest
    /// frequency `omega_max` along the orbit, and the generators `kept` from the last analysis.
    pub(crate) fn new(
        sys: &'c Coordinates<'m>,
        (omega, scale_q, scale_v, omega_max): (f64, f64, f64, f64),
        max_steps: usize,
        kept: KeptGenerators,
    ) -> Result<Self> {
        let n = sys.len();
        let m_inv = sys
            .mass
            .clone()
            .cholesky()
            .ok_or_else(|| Error::MassNotPositiveDefinite {
                reason: "Cholesky factorisation failed".into(),
            })?
            .inverse();
        let omega_s = scale_v / scale_q;
        let mut base = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            base[(i, n + i)] = omega_s;
        }
        base.view_mut((n, 0), (n, n))
            .copy_from(&(-(&m_inv * &sys.stiffness) / omega_s));
        base.view_mut((n, n), (n, n))
            .copy_from(&(-(&m_inv * &sys.damping)));
        let mw: Vec<DVector<f64>> = sys
            .weights
            .iter()
            .map(|w| {
                DVector::from_fn(n, |i, _| {
                    w.iter().map(|&(j, wj)| m_inv[(i, j)] * wj).sum::<f64>()
                })
            })
            .collect();
        let forcing = Forcing::new(sys, &m_inv, scale_v, omega);
        let fastest = omega_max.max(omega).max(forcing.top());
        let delta0 = f64::powi(2.0, -(fastest.log2().ceil() as i32));
        let turns = forcing.turns(delta0);
        let (cores, spare) = kept.split();
        let assembler = Box::new(Assembler::new(2 * n, &sys.weights, &mw).with_spare(spare));
        let pieces = Pieces::new(sys);
        let kinks = Kinked::new(sys, |e| pieces.has_kinks(e), scale_q, scale_v);
        Ok(Self {
            sys,
            n,
            omega,
            bounds: crate::timesim::segment_bounds(sys.model),
            pieces,
            scale_q,
            scale_v,
            delta0,
            max_steps,
            base,
            mw,
            forcing,
            turns,
            work: ExpWork::new(2 * n),
            states: Vec::new(),
            cores,
            index: WordMap::default(),
            taylor: Expansion::default(),
            kinks,
            steps: 0,
            assembler,
            link: None,
            monodromy_only: false,
        })
    }

    /// The piece the scaled state `x̃` is in, laws evaluated at angle `theta`.
    pub(crate) fn piece(&mut self, theta: f64) -> Piece {
        let n = self.n;
        let mut coefficients = Vec::with_capacity(self.mw.len());
        let mut key = Vec::with_capacity(3 * self.mw.len());
        for e in 0..self.mw.len() {
            let u = self.pieces.inside(e);
            let (f, k, d) = self.pieces.law(self.sys, e, theta, u, 0.0);
            let f0 = f - k * u;
            coefficients.push((f0, k, d));
            key.extend([f0.to_bits(), k.to_bits(), d.to_bits()]);
        }
        let state = match self.index.get(&key) {
            Some(&i) => i,
            None => {
                let omega_s = self.scale_v / self.scale_q;
                let mut a = self.base.clone();
                let mut offset = DVector::zeros(2 * n);
                for (e, (&(f0, k, d), mw)) in coefficients.iter().zip(&self.mw).enumerate() {
                    for i in 0..n {
                        offset[n + i] -= f0 * mw[i] / self.scale_v;
                    }
                    for &(j, wj) in &self.sys.weights[e] {
                        for i in 0..n {
                            a[(n + i, j)] -= k / omega_s * mw[i] * wj;
                            a[(n + i, n + j)] -= d * mw[i] * wj;
                        }
                    }
                }
                let (fine, degree) = Core::fine(norm1(&a), &self.forcing, self.delta0);
                let core = self.cores.core(a, self.delta0, fine, &mut self.work);
                let s = if self.monodromy_only {
                    State::without_load(core, offset)
                } else {
                    State::new(core, degree, offset, &self.forcing, self.delta0)
                };
                if let Some(link) = &mut self.link {
                    link.send(Message::Generator(s.core.clone()));
                }
                self.states.push(s);
                self.index.insert(key, self.states.len() - 1);
                self.states.len() - 1
            }
        };
        Piece {
            state,
            coefficients,
        }
    }

    /// The generators of this analysis, for the next (the assembler back on this thread).
    pub(crate) fn kept(&mut self) -> KeptGenerators {
        KeptGenerators::join(
            std::mem::take(&mut self.cores),
            self.assembler.take_propagators(),
        )
    }

    /// `true` if every law at `x̃` and `theta` still has the piece's coefficients.
    fn still_affine(&self, piece: &Piece, x: &DVector<f64>, theta: f64) -> bool {
        self.coefficients_hold(piece, theta, |e| self.element_state(e, x))
    }

    /// `true` if every law `e` at `theta` and `state(e) = (u, u̇)` has the piece's
    /// coefficients (to 1e-9).
    pub(crate) fn coefficients_hold(
        &self,
        piece: &Piece,
        theta: f64,
        state: impl Fn(usize) -> (f64, f64),
    ) -> bool {
        piece
            .coefficients
            .iter()
            .enumerate()
            .all(|(e, &(f0, k, d))| {
                let (u, du) = state(e);
                let (f, k1, d1) = self.pieces.law(self.sys, e, theta, u, du);
                let close = |a: f64, b: f64, size: f64| (a - b).abs() <= 1e-9 * size;
                close(k, k1, k.abs().max(k1.abs()))
                    && close(d, d1, d.abs().max(d1.abs()))
                    && close(
                        f,
                        f0 + k * u + d * du,
                        f.abs() + f0.abs() + (k * u).abs() + (d * du).abs(),
                    )
            })
    }

    /// Integrates the state `y = (q, q̇)` over one period `[0, T]` and appends its pieces to
    /// `record` (what [`ExpFlow::monodromy`] multiplies). `Ok(false)`: a law is not affine on
    /// its piece (`y` is then meaningless; use the Runge–Kutta flow).
    pub(crate) fn orbit(&mut self, y: &mut [f64], record: &mut Vec<Step>) -> Result<bool> {
        let n = self.n;
        let s2 = 2 * n;
        let mut x = DVector::from_fn(s2, |i, _| {
            y[i] / if i < n { self.scale_q } else { self.scale_v }
        });
        let mut z = DVector::zeros(self.forcing.states());
        let mut x_new = DVector::zeros(s2);
        let kinked = 2 * self.kinks.elements.len();
        let (mut at_start, mut at_end) = (vec![0.0; kinked], vec![0.0; kinked]);
        self.pieces.init(self.sys, &y[..n], &y[n..s2]);
        let (omega, delta0) = (self.omega, self.delta0);
        let bounds = self.bounds.clone();
        let steps_at_start = self.steps;
        for w in bounds.windows(2) {
            let (ta, tb) = (w[0] / omega, w[1] / omega);
            let margin = 1e-9 * (w[1] - w[0]);
            let angle = |t: f64| (w[0] + omega * (t - ta)).clamp(w[0] + margin, w[1] - margin);
            let mut t = ta;
            while tb - t > 1e-14 * tb.abs().max(1.0 / omega) {
                let whole = ((tb - t) / delta0).floor();
                if self.steps - steps_at_start + whole as usize > self.max_steps {
                    return Err(Error::Solver {
                        reason: format!(
                            "Floquet integration needed more than {} steps in one period",
                            self.max_steps
                        ),
                    });
                }
                let piece = self.piece(angle(0.5 * (t + tb)));
                let state = &self.states[piece.state];
                // Whole sub-steps until a crossing.
                let mut done = 0;
                let mut hit = None;
                self.kink_states(&x, &mut at_start);
                self.kinks.refresh(&self.pieces, self.scale_q);
                self.forcing.oscillator(t, &mut z);
                for _ in 0..whole as usize {
                    let terms = [(state.e0(), x.as_slice()), (&state.x0, z.as_slice())];
                    gemv_sum(&terms, x_new.as_mut_slice(), false);
                    self.kink_states(&x_new, &mut at_end);
                    hit = self.first_crossing(&at_start, &at_end, delta0);
                    if hit.is_some() {
                        break;
                    }
                    std::mem::swap(&mut x, &mut x_new);
                    std::mem::swap(&mut at_start, &mut at_end);
                    self.forcing.advance(&self.turns, &mut z);
                    done += 1;
                }
                let t_sub = t + done as f64 * delta0;
                // The last part: up to the crossing, or the remainder.
                let (tau, crossed) = if let Some((s, e, up)) = hit {
                    let state = &self.states[piece.state];
                    self.taylor.expand(state, &self.forcing, &x, t_sub, delta0);
                    (
                        self.locate(&mut x, s * delta0, delta0, e, up),
                        Some((e, up)),
                    )
                } else {
                    let r = (tb - t_sub).max(0.0);
                    let state = &self.states[piece.state];
                    self.taylor.expand(state, &self.forcing, &x, t_sub, r);
                    self.taylor.evaluate(r, &mut x_new);
                    self.kink_states(&x_new, &mut at_end);
                    match self.first_crossing(&at_start, &at_end, r) {
                        Some((s, e, up)) => (self.locate(&mut x, s * r, r, e, up), Some((e, up))),
                        None => {
                            std::mem::swap(&mut x, &mut x_new);
                            (r, None)
                        }
                    }
                };
                self.steps += done + 1;
                // For the monodromy matrix: Φ̃ ← e^{Ãτ} E_δ₀^done Φ̃.
                self.emit(
                    record,
                    Step::Piece {
                        state: piece.state,
                        whole: done,
                        tau,
                    },
                );
                let end = if crossed.is_some() { t_sub + tau } else { tb };
                if !self.still_affine(&piece, &x, angle(end)) {
                    return Ok(false);
                }
                if let Some((e, up)) = crossed {
                    if let Some(factor) = self.cross(e, up, angle(end), &x) {
                        self.emit(record, Step::Jump { element: e, factor });
                    }
                }
                t = end;
            }
        }
        for i in 0..s2 {
            y[i] = x[i] * if i < n { self.scale_q } else { self.scale_v };
        }
        if y[..s2].iter().any(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "orbit (exponential flow)".into(),
            });
        }
        Ok(true)
    }
}
