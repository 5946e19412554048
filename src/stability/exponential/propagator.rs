//! The factors of the monodromy matrix per generator `Ã` of the exponential flow
//! ([`record`](super::record)): a piece `h = m δ₀ + τ` multiplies `Φ̃` by `E_δ₀^m` and then
//! by `e^{Ãτ}`.
//!
//! **Whole sub-steps.** The ladder `L_j = E_δ₀^{2^j}`, squared on demand, gives
//! `E_δ₀^m = Π_{bits j of m} L_j`. The pieces of a generator come back with the same few `m`
//! (the meshing repeats tooth after tooth: about 140 distinct `(Ã, m)` with two or more bits
//! among the 1 344 pieces of a period of the drivetrain), so `E_δ₀^m` is kept once formed: a
//! piece's whole sub-steps cost one product instead of one per set bit.
//!
//! **Last part.** For `‖Ãτ‖₁ <= 1` (the last parts are shorter than `δ₀`) the Taylor
//! polynomial `Σ_{i<=d} τⁱ (Ãⁱ/i!)` from the kept terms, `d` the first degree whose next term
//! is below 1e-16 of the norm (at most 16): a linear combination, no product
//! ([`horner`](super::kernels::horner)); scaling and squaring otherwise.

use super::expm::{inverse_factorial, ExpWork};
use super::generator::Core;
use super::kernels::{horner, product, product_scaled};
use nalgebra::DMatrix;
use std::collections::HashMap;
use std::sync::Arc;

/// The most powers `E_δ₀^m` a propagator keeps from one point of a sweep to the next.
const WHOLE_KEPT: usize = 256;

/// The monodromy side of one generator.
#[derive(Clone)]
pub(crate) struct Propagator {
    core: Arc<Core>,
    /// `L_j = E_δ₀^{2^j}` for `j >= 1` (`L_0 = E_δ₀` is the core's).
    ladder: Vec<DMatrix<f64>>,
    /// `E_δ₀^m` by `m`, for `m` with two or more set bits.
    whole: HashMap<usize, DMatrix<f64>>,
    /// `Ãⁱ/i!`, `i = 0..=16`, formed at the first short exponential.
    terms: Vec<DMatrix<f64>>,
}

impl Propagator {
    pub(crate) fn new(core: Arc<Core>) -> Self {
        Self {
            core,
            ladder: Vec::new(),
            whole: HashMap::new(),
            terms: Vec::new(),
        }
    }

    /// The generator's core.
    pub(crate) fn core(&self) -> &Arc<Core> {
        &self.core
    }

    /// Forgets the powers `E_δ₀^m` if there are many (a sweep's pieces change length with
    /// the speed: the ones met long ago are not met again).
    pub(crate) fn trim(&mut self) {
        if self.whole.len() > WHOLE_KEPT {
            self.whole.clear();
        }
    }

    /// `L_j`, the ladder extended as far as needed.
    fn rung(&mut self, j: usize) -> &DMatrix<f64> {
        while self.ladder.len() < j {
            let last = self.ladder.last().unwrap_or(&self.core.e0);
            let mut next = DMatrix::zeros(last.nrows(), last.ncols());
            product(last, last, &mut next);
            self.ladder.push(next);
        }
        if j == 0 {
            &self.core.e0
        } else {
            &self.ladder[j - 1]
        }
    }

    /// `phi ← E_δ₀^k phi` (`tmp` a buffer of its shape).
    pub(crate) fn advance(&mut self, k: usize, phi: &mut DMatrix<f64>, tmp: &mut DMatrix<f64>) {
        if k == 0 {
            return;
        }
        if k.count_ones() == 1 {
            product(self.rung(k.trailing_zeros() as usize), phi, tmp);
            std::mem::swap(phi, tmp);
            return;
        }
        if !self.whole.contains_key(&k) {
            // E^k = L_{j_last} ⋯ L_{j_1} L_{j_0} over the set bits j of k.
            let mut power = self.rung(k.trailing_zeros() as usize).clone();
            let mut buffer = DMatrix::zeros(power.nrows(), power.ncols());
            let mut rest = k & (k - 1);
            while rest != 0 {
                product(
                    self.rung(rest.trailing_zeros() as usize),
                    &power,
                    &mut buffer,
                );
                std::mem::swap(&mut power, &mut buffer);
                rest &= rest - 1;
            }
            self.whole.insert(k, power);
        }
        product(&self.whole[&k], phi, tmp);
        std::mem::swap(phi, tmp);
    }

    /// `out = e^{Ãτ}`.
    pub(crate) fn exp_short(&mut self, tau: f64, out: &mut DMatrix<f64>, work: &mut ExpWork) {
        let p = &self.core.powers;
        let x = p.norm * tau.abs();
        if x > 1.0 {
            work.exp(p, tau, out);
            return;
        }
        if self.terms.is_empty() {
            let m = p.a.nrows();
            self.terms = vec![
                DMatrix::identity(m, m),
                p.a.clone(),
                p.a2() / 2.0,
                p.a3() / 6.0,
                p.a4() / 24.0,
            ];
            for i in 5..=16 {
                let mut next = DMatrix::zeros(m, m);
                product_scaled(1.0 / i as f64, &self.terms[i - 1], &p.a, &mut next);
                self.terms.push(next);
            }
        }
        let degree = (1..16)
            .find(|&d| x.powi(d as i32 + 1) * inverse_factorial(d + 1) < 1e-16)
            .unwrap_or(16);
        horner(&self.terms[..=degree], tau, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_sub_steps_are_the_power_of_the_sub_step() {
        let m = 6;
        let a = DMatrix::from_fn(m, m, |i, j| ((i * 5 + j * 3) as f64).sin() * 0.2);
        let mut prop =
            Propagator::new(Arc::new(Core::new(a.clone(), 0.1, 0, &mut ExpWork::new(m))));
        let start = DMatrix::from_fn(m, m, |i, j| ((i + 2 * j) as f64).cos());
        let mut tmp = DMatrix::zeros(m, m);
        // Twice each (the second from the kept power), and a single bit.
        for k in [13, 13, 6, 8, 1, 0] {
            let mut phi = start.clone();
            prop.advance(k, &mut phi, &mut tmp);
            let exact = (&a * (0.1 * k as f64)).exp() * &start;
            assert!((&phi - &exact).amax() < 1e-13, "k = {k}");
        }
        let mut out = DMatrix::zeros(m, m);
        prop.exp_short(0.037, &mut out, &mut ExpWork::new(m));
        assert!((&out - (&a * 0.037).exp()).amax() < 1e-15);
    }
}
