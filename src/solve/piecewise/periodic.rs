//! The periodic state (one solve with `I - Φ`) and the closed-form harmonics of a
//! [`Schedule`] ([module docs](super)).

use super::factor::ComplexLu;
use super::phasors::EdgePhasors;
use super::schedule::{self, Schedule};
use crate::error::{Error, Result};
use crate::stability::expm::ExpWork;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The periodic state at the start of every piece.
pub(super) struct Periodic {
    /// `h_p = x(t_p) - x_p(t_p)`, the free motion at the start of piece p (state `(q, q̇)`).
    pub(super) free_start: Vec<DVector<f64>>,
    /// `Φ_p h_p`, the free motion at its end.
    pub(super) free_end: Vec<DVector<f64>>,
    /// `|x(T) - x(0)| / |x(0)|` after propagating the solved `x(0)` once more.
    pub(super) closure: f64,
    /// Largest over smallest pivot of the LU of `I - Φ` (scaled state).
    pub(super) condition: f64,
    /// The eigenvalues of `Φ` (those of the scaled and the unscaled `Φ` are one), by
    /// decreasing modulus.
    pub(super) multipliers: Vec<Complex64>,
}

impl Schedule {
    /// Solves `(I - Φ) x(0) = c` in the scaled state `(q, q̇/ω_s)` and propagates the periodic
    /// state through the pieces.
    pub(super) fn periodic_state(&self) -> Result<Periodic> {
        let m = 2 * self.n;
        let mut phi = DMatrix::<f64>::identity(m, m);
        let mut c = DVector::<f64>::zeros(m);
        let mut work = ExpWork::new(m);
        let mut transitions = Vec::with_capacity(self.pieces.len());
        let steady = |piece: &schedule::Piece, at_end: bool| {
            let config = &self.configurations[piece.configuration];
            let theta = if at_end { piece.end } else { piece.start };
            self.scale_state(config.steady_state(theta, self.omega))
        };
        for piece in &self.pieces {
            let config = &self.configurations[piece.configuration];
            let mut t = DMatrix::zeros(m, m);
            work.exp(&config.generator, piece.duration(self.omega), &mut t);
            c = &t * (c - steady(piece, false)) + steady(piece, true);
            phi = &t * phi;
            transitions.push(t);
        }
        if !(phi.iter().all(|v| v.is_finite()) && c.iter().all(|v| v.is_finite())) {
            return Err(Error::NonFinite {
                what: "the monodromy matrix of the exact piecewise solution".into(),
            });
        }
        let mut multipliers: Vec<Complex64> = phi.complex_eigenvalues().iter().copied().collect();
        multipliers.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
        // A free body's shift adds 2p multipliers below e^{-40} (module free_body).
        let kept = multipliers.len().saturating_sub(2 * self.rigid_modes());
        multipliers.truncate(kept);
        let mut a = DMatrix::<f64>::identity(m, m) - &phi;
        let mut perm = vec![0; m];
        let regular = crate::solve::lu::factor_in_place(&mut a, &mut perm);
        let pivots = (0..m).map(|i| a[(i, i)].abs());
        let (lo, hi) = pivots.fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
        if !regular || lo <= f64::EPSILON * hi {
            return Err(Error::Solver {
                reason: "piecewise_exact: the monodromy matrix has a multiplier 1 (I - Φ is singular): an undamped or rigid-body motion without a unique periodic solution".into(),
            });
        }
        let mut x0 = c.clone();
        crate::solve::lu::solve_in_place(&a, &perm, x0.as_mut_slice());
        let mut x = x0.clone();
        let mut free_start = Vec::with_capacity(self.pieces.len());
        let mut free_end = Vec::with_capacity(self.pieces.len());
        for (piece, t) in self.pieces.iter().zip(&transitions) {
            let h = &x - steady(piece, false);
            let e = t * &h;
            x = steady(piece, true) + &e;
            free_start.push(self.unscale_state(h));
            free_end.push(self.unscale_state(e));
        }
        let closure = (&x - &x0).norm() / x0.norm().max(f64::MIN_POSITIVE);
        Ok(Periodic {
            free_start,
            free_end,
            closure,
            condition: hi / lo,
            multipliers,
        })
    }

    /// The one-sided harmonics `Q_l`, `l = 0..=orders`, of the periodic solution
    /// (`Q[l n + i]`).
    pub(super) fn harmonics(&self, periodic: &Periodic, orders: usize) -> Result<Vec<Complex64>> {
        let n = self.n;
        let mut out = vec![Complex64::new(0.0, 0.0); (orders + 1) * n];
        let mut lu = ComplexLu::new(n);
        let mut rhs = vec![Complex64::new(0.0, 0.0); n];
        let mut r = vec![Complex64::new(0.0, 0.0); 2 * n];
        let scale = self.omega / TAU;
        let loads = self.model_load_orders;
        let mut edges: Vec<EdgePhasors> = self
            .pieces
            .iter()
            .map(|p| EdgePhasors::new(p.start, p.end, loads))
            .collect();
        for l in 0..=orders {
            let s = Complex64::new(0.0, l as f64 * self.omega);
            let two_sided = &mut out[l * n..(l + 1) * n];
            for e in edges.iter_mut() {
                e.go_to(l);
            }
            for (ci, config) in self.configurations.iter().enumerate() {
                let mut factored = false;
                for (p, piece) in self.pieces.iter().enumerate() {
                    if piece.configuration != ci {
                        continue;
                    }
                    let edge = &edges[p];
                    config.add_steady_window(edge, two_sided);
                    if !factored {
                        config.factor_dynamic_stiffness(&self.mass, s, &mut lu, l, self.omega)?;
                        factored = true;
                    }
                    // r = e^{-sτ} Φ h - h, then y = -Z⁻¹ (M r_v + (D + sM) r_q).
                    // e^{-sτ} = e^{-il(b - a)}.
                    let decay = edge.eb * edge.ea.conj();
                    let (h, e) = (&periodic.free_start[p], &periodic.free_end[p]);
                    for (ri, (ei, hi)) in r.iter_mut().zip(e.iter().zip(h.iter())) {
                        *ri = decay * ei - hi;
                    }
                    let (rq, rv) = r.split_at(n);
                    for (i, b) in rhs.iter_mut().enumerate() {
                        let mut acc = Complex64::new(0.0, 0.0);
                        for j in 0..n {
                            acc += self.mass[(i, j)] * (rv[j] + s * rq[j])
                                + config.damping[(i, j)] * rq[j];
                        }
                        *b = -acc;
                    }
                    lu.solve(&mut rhs);
                    let phase = scale * edge.ea;
                    for (o, y) in two_sided.iter_mut().zip(&rhs) {
                        *o += phase * y;
                    }
                }
            }
            if l > 0 {
                for o in two_sided.iter_mut() {
                    *o *= 2.0;
                }
            }
        }
        Ok(out)
    }
}
