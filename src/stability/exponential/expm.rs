//! Matrix functions of the small dense generators of the exponential flow
//! ([`exponential`](super::exp_flow)).
//!
//! **Exponential.** For `‖Z‖₁ <= 1` the Taylor polynomial of degree 16,
//! `T(Z) = Σ_{i<=16} Zⁱ/i!`, differs from `e^Z` by at most `Σ_{i>16} 1/i! < 3e-15` (degree 12
//! for `‖Z‖₁ <= 0.33` and 8 for `<= 0.07` keep the first omitted term below 1e-16); it is
//! evaluated by Paterson–Stockmeyer: `Z², Z³, Z⁴`, then
//! `T = B₀ + Z⁴(B₁ + Z⁴(B₂ + Z⁴(B₃ + Z⁴/16!)))` with `B_k = Σ_{i<4} Z^i/(4k+i)!`. For
//! `Z = δA` the powers are `δⁱAⁱ`: with `A², A³, A⁴` kept per generator ([`Powers`]) an
//! exponential costs three matrix products. A larger argument is scaled,
//! `e^{Z} = (e^{Z/2^s})^{2^s}`.
//!
//! **φ-functions.** `φ_j(Z) = Σ_{i>=0} Zⁱ/(i+j)!` (`φ_0 = exp`), so that
//! `∫₀^δ e^{(δ-s)A} sʲ/j! ds = δ^{j+1} φ_{j+1}(δA)`: the exact response to a polynomial forcing.
//! On a narrow block `V` (a few columns) the highest one, `φ_{p+1}(Z) V`, is summed by Horner's
//! rule and the others follow from `φ_j(Z) = Z φ_{j+1}(Z) + I/j!`.

use super::kernels::{product, product_scaled};
use nalgebra::DMatrix;

/// `1/i!` for `i <= 24`.
pub(crate) fn inverse_factorial(i: usize) -> f64 {
    inverse_factorials()[i]
}

/// Reciprocal factorials `1/i!`, `i = 0..=24`.
fn inverse_factorials() -> [f64; 25] {
    let mut f = [1.0; 25];
    for i in 1..25 {
        f[i] = f[i - 1] / i as f64;
    }
    f
}

/// A generator `A` with the powers `A², A³, A⁴` of the Paterson–Stockmeyer scheme: for
/// `Z = δA` they are `δⁱAⁱ`, so a cached generator costs three products per exponential.
pub(crate) struct Powers {
    pub(crate) a: DMatrix<f64>,
    a2: DMatrix<f64>,
    a3: DMatrix<f64>,
    a4: DMatrix<f64>,
    /// `‖A‖₁`.
    pub(crate) norm: f64,
}

impl Powers {
    pub(crate) fn a2(&self) -> &DMatrix<f64> {
        &self.a2
    }

    pub(crate) fn a3(&self) -> &DMatrix<f64> {
        &self.a3
    }

    pub(crate) fn a4(&self) -> &DMatrix<f64> {
        &self.a4
    }

    pub(crate) fn new(a: DMatrix<f64>) -> Self {
        let square = || DMatrix::zeros(a.nrows(), a.ncols());
        let (mut a2, mut a3, mut a4) = (square(), square(), square());
        product(&a, &a, &mut a2);
        product(&a2, &a, &mut a3);
        product(&a2, &a2, &mut a4);
        let norm = norm1(&a);
        Self {
            a,
            a2,
            a3,
            a4,
            norm,
        }
    }
}

/// Buffers for the products of one size (no allocation per call).
pub(crate) struct ExpWork {
    acc: DMatrix<f64>,
    tmp: DMatrix<f64>,
}

impl ExpWork {
    pub(crate) fn new(m: usize) -> Self {
        Self {
            acc: DMatrix::zeros(m, m),
            tmp: DMatrix::zeros(m, m),
        }
    }

    /// `out = T(δA)`, the Taylor polynomial of `e^{δA}` (accurate for `‖δA‖₁ <= 1`) of degree
    /// 8, 12 or 16 by the norm, in one to three products from the cached powers.
    pub(crate) fn taylor(&mut self, p: &Powers, delta: f64, out: &mut DMatrix<f64>) {
        let c = inverse_factorials();
        let m = p.a.nrows();
        let (d1, d2, d3) = (delta, delta * delta, delta * delta * delta);
        let d4 = d2 * d2;
        // B_k = c_{4k} I + c_{4k+1} Z + c_{4k+2} Z² + c_{4k+3} Z³ into `dst` (Z = δA).
        let block = |k: usize, dst: &mut DMatrix<f64>, add: bool| {
            let (x, y, z) = (c[4 * k + 1] * d1, c[4 * k + 2] * d2, c[4 * k + 3] * d3);
            let (a, a2, a3) = (p.a.as_slice(), p.a2.as_slice(), p.a3.as_slice());
            for (i, v) in dst.as_mut_slice().iter_mut().enumerate() {
                let w = x * a[i] + y * a2[i] + z * a3[i];
                *v = if add { *v + w } else { w };
            }
            for j in 0..m {
                dst[(j, j)] += c[4 * k];
            }
        };
        // Degree 4m: 8 for ‖Z‖₁ <= 0.07, 12 for <= 0.33, else 16 (the first omitted term
        // below 1e-16 for the first two, 3e-15 at ‖Z‖₁ = 1).
        let norm = p.norm * delta.abs();
        let m4 = if norm <= 0.07 {
            2
        } else if norm <= 0.33 {
            3
        } else {
            4
        };
        // acc = B_{m-1} + Z⁴/(4m)!, then acc = B_k + Z⁴ acc for k = m-2, …, 0.
        let mut acc = std::mem::replace(&mut self.acc, DMatrix::zeros(0, 0));
        block(m4 - 1, &mut acc, false);
        add_scaled(&mut acc, c[4 * m4] * d4, &p.a4);
        for k in (0..m4 - 1).rev() {
            product_scaled(d4, &p.a4, &acc, &mut self.tmp);
            std::mem::swap(&mut acc, &mut self.tmp);
            block(k, &mut acc, true);
        }
        out.copy_from(&acc);
        self.acc = acc;
    }

    /// `out = e^{At}` by scaling and squaring the Taylor polynomial.
    pub(crate) fn exp(&mut self, p: &Powers, t: f64, out: &mut DMatrix<f64>) {
        let s = squarings(p.norm * t.abs());
        self.taylor(p, t / f64::powi(2.0, s as i32), out);
        for _ in 0..s {
            product(out, out, &mut self.tmp);
            out.copy_from(&self.tmp);
        }
    }
}

/// The number of halvings that bring a 1-norm `x` to at most 1.
pub(crate) fn squarings(x: f64) -> u32 {
    if x <= 1.0 || !x.is_finite() {
        0
    } else {
        x.log2().ceil().max(0.0) as u32
    }
}

/// `a += c b`.
fn add_scaled(a: &mut DMatrix<f64>, c: f64, b: &DMatrix<f64>) {
    for (x, y) in a.as_mut_slice().iter_mut().zip(b.as_slice()) {
        *x += c * y;
    }
}

/// `max_j Σ_i |a_ij|`.
pub(crate) fn norm1(a: &DMatrix<f64>) -> f64 {
    a.column_iter()
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// `out[j] = φ_{j+1}(z) v` for `j = 0..=p` (`‖z‖₁ <= 1`; `out` has `p + 1` blocks shaped like
/// `v`; `tmp` one more).
pub(crate) fn phi_narrow(
    z: &DMatrix<f64>,
    v: &DMatrix<f64>,
    out: &mut [DMatrix<f64>],
    tmp: &mut DMatrix<f64>,
) {
    let c = inverse_factorials();
    let p = out.len() - 1;
    // φ_{p+1}(Z) V = Σ_{i<=N} Zⁱ V / (i+p+1)!, with (N+p+2)! > 1e17: N + p + 2 = 20.
    let terms = 18 - p;
    let top = &mut out[p];
    top.copy_from(v);
    *top *= c[terms + p + 1];
    for i in (0..terms).rev() {
        product(z, top, tmp);
        top.copy_from(tmp);
        add_scaled(top, c[i + p + 1], v);
    }
    for j in (1..=p).rev() {
        // φ_j V = Z φ_{j+1} V + V/j!
        let (lo, hi) = out.split_at_mut(j);
        product(z, &hi[0], &mut lo[j - 1]);
        add_scaled(&mut lo[j - 1], c[j], v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(m: usize, scale: f64, seed: u64) -> DMatrix<f64> {
        let mut s = seed;
        DMatrix::from_fn(m, m, |_, _| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * scale
        })
    }

    #[test]
    fn the_exponential_matches_nalgebra_and_a_rotation() {
        // A rotation generator: e^{[[0, -w], [w, 0]] t} = [[cos wt, -sin wt], [sin wt, cos wt]].
        let a = DMatrix::from_row_slice(2, 2, &[0.0, -3.0, 3.0, 0.0]);
        let mut out = DMatrix::zeros(2, 2);
        ExpWork::new(2).exp(&Powers::new(a), 7.3, &mut out);
        let (s, c) = (3.0_f64 * 7.3).sin_cos();
        let exact = DMatrix::from_row_slice(2, 2, &[c, -s, s, c]);
        assert!((&out - &exact).amax() < 1e-13, "{out} {exact}");
        // A damped, stiff 12 × 12 generator with norm 40 against nalgebra's Padé.
        let mut a = sample(12, 10.0, 3);
        for i in 0..12 {
            a[(i, i)] -= 15.0;
        }
        let mut out = DMatrix::zeros(12, 12);
        let reference = a.clone().exp();
        let powers = Powers::new(a);
        ExpWork::new(12).exp(&powers, 1.0, &mut out);
        let err = (&out - &reference).amax() / reference.amax();
        assert!(err < 1e-12, "{err:e}");
        // Short steps take the degree-8 and degree-12 polynomials.
        for t in [1e-3, 6e-3, 2e-2] {
            let mut short = DMatrix::zeros(12, 12);
            ExpWork::new(12).exp(&powers, t, &mut short);
            let exact = (&powers.a * t).exp();
            let err = (&short - &exact).amax() / exact.amax();
            assert!(err < 4e-15, "t = {t}: {err:e}");
        }
        // A product of half steps is the full step.
        let mut half = DMatrix::zeros(12, 12);
        ExpWork::new(12).exp(&powers, 0.5, &mut half);
        assert!((&half * &half - &out).amax() / out.amax() < 1e-12);
    }

    #[test]
    fn phi_functions_give_the_response_to_a_polynomial_forcing() {
        // y' = a y + (b₀ + b₁ s + b₂ s²/2) on [0, δ] from y = 0, against the augmented
        // exponential of [[a δ, δ B], [0, shift]] with B = [b₀ b₁ b₂] (the exact answer).
        let m = 6;
        let a = sample(m, 1.5, 11);
        let b = sample(m, 1.0, 12).columns(0, 3).into_owned();
        // A step inside the series' range, ‖a δ‖₁ ≤ 1 (as the flow chooses it).
        let delta = 0.9 / norm1(&a);
        let z = &a * delta;
        assert!(norm1(&z) <= 1.0);
        let mut out = vec![DMatrix::zeros(m, 3); 3];
        let mut tmp = DMatrix::zeros(m, 3);
        phi_narrow(&z, &b, &mut out, &mut tmp);
        // φ_{j+1}(Z) b_j: the j-th block's column j.
        let y: nalgebra::DVector<f64> = (0..3)
            .map(|j| out[j].column(j) * delta.powi(j as i32 + 1))
            .fold(nalgebra::DVector::zeros(m), |acc, x| acc + x);
        let mut aug = DMatrix::zeros(m + 3, m + 3);
        aug.view_mut((0, 0), (m, m)).copy_from(&z);
        // z' = J z with z = (s²/2, s, 1): the forcing b₂ z₀ + b₁ z₁ + b₀ z₂.
        for (col, j) in [(m, 2), (m + 1, 1), (m + 2, 0)] {
            aug.view_mut((0, col), (m, 1))
                .copy_from(&(b.column(j) * delta));
        }
        aug[(m, m + 1)] = delta;
        aug[(m + 1, m + 2)] = delta;
        let e = aug.exp();
        let exact = e.view((0, m + 2), (m, 1)).into_owned();
        let err = (&y - exact.column(0)).amax();
        assert!(err < 1e-14, "{err:e}");
    }
}
