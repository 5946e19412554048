//! The extremes of a solution over one period: sampled, then refined by Newton on `q'(θ) = 0`
//! with the analytic derivatives of the harmonics.

use super::Solution;
use crate::harmonic::HarmonicBasis;
use num_complex::Complex64;

impl Solution {
    /// `max |q_dof|` over one period, to the precision of the harmonics (see
    /// [`Solution::extremes`]).
    ///
    /// ```
    /// use hbal::{HarmonicBasis, Solution};
    /// use num_complex::Complex64;
    /// // q = 2 cos(θ - 0.1234): its maximum lies between any samples.
    /// let q = vec![Complex64::new(0.0, 0.0), Complex64::from_polar(2.0, -0.1234)];
    /// let basis = HarmonicBasis::new(1.0, 1).unwrap();
    /// let sol = Solution::from_harmonics(basis, vec!["x".into()], q, 0.0).unwrap();
    /// assert!((sol.max_abs(0) - 2.0).abs() < 1e-14);
    /// ```
    pub fn max_abs(&self, dof: usize) -> f64 {
        let (lo, hi) = self.extremes(dof);
        lo.abs().max(hi.abs())
    }

    /// `(min q_dof, max q_dof)` over one period: the extremes of 4N samples (at least 64),
    /// each refined by Newton on `q'(θ) = 0` with the analytic derivatives of the harmonics
    /// (within one sample spacing), so exact to rounding instead of to the sampling's
    /// `O((π/4N)²)`.
    pub fn extremes(&self, dof: usize) -> (f64, f64) {
        let points = self.extreme_points();
        let series = self.time_series(dof, points);
        extremes_of(&self.dof_harmonics(dof), &series)
    }

    /// [`Solution::extremes`] of every DOF, with one FFT plan for all (a large model's sweep
    /// point: planning per DOF cost more than the transforms).
    pub fn extremes_all(&self) -> Vec<(f64, f64)> {
        let n = self.dofs.len();
        let h = self.basis.harmonics();
        let points = self.extreme_points();
        let plan = HarmonicBasis::new(self.basis.omega(), h)
            .and_then(|b| b.with_samples(points))
            .ok()
            .filter(|_| n > 1 && points > 2 * h)
            .map(crate::harmonic::AftPlan::new);
        let Some(plan) = plan else {
            return (0..n).map(|i| self.extremes(i)).collect();
        };
        let mut scratch = plan.make_scratch();
        let mut q = vec![Complex64::default(); h + 1];
        let mut series = vec![0.0; points];
        (0..n)
            .map(|dof| {
                for (k, qk) in q.iter_mut().enumerate() {
                    *qk = self.harmonics[k * n + dof];
                }
                plan.synthesize_into(&q, |_| Complex64::new(1.0, 0.0), &mut series, &mut scratch);
                extremes_of(&q, &series)
            })
            .collect()
    }

    /// `max |q_i|` of every DOF (see [`Solution::extremes_all`]).
    pub fn max_abs_all(&self) -> Vec<f64> {
        self.extremes_all()
            .into_iter()
            .map(|(lo, hi)| lo.abs().max(hi.abs()))
            .collect()
    }

    /// Samples the extremes are searched on: 4N, at least 64.
    fn extreme_points(&self) -> usize {
        (4 * self.basis.samples()).max(64)
    }

    /// The harmonics `0..=H` of `dof`, contiguous.
    fn dof_harmonics(&self, dof: usize) -> Vec<Complex64> {
        (0..=self.basis.harmonics())
            .map(|k| self.harmonic(dof, k))
            .collect()
    }
}

/// The refined extremes of the series with harmonics `q` (`0..=H`) from its samples `series`
/// over one period.
fn extremes_of(q: &[Complex64], series: &[f64]) -> (f64, f64) {
    let (imin, imax) = arg_extremes(series);
    let lo = refine_extremum(q, series, imin, -1.0);
    let hi = refine_extremum(q, series, imax, 1.0);
    (lo, hi)
}

/// The first indices of the smallest and the largest sample (0 for a series without an
/// ordered value). The extremes in lanes of 8, which vectorise, then their first positions.
fn arg_extremes(series: &[f64]) -> (usize, usize) {
    const LANES: usize = 8;
    let (mut lo, mut hi) = ([f64::INFINITY; LANES], [f64::NEG_INFINITY; LANES]);
    let chunks = series.chunks_exact(LANES);
    let rest = chunks.remainder();
    for c in chunks {
        for i in 0..LANES {
            lo[i] = if c[i] < lo[i] { c[i] } else { lo[i] };
            hi[i] = if c[i] > hi[i] { c[i] } else { hi[i] };
        }
    }
    let mut low = lo.iter().copied().fold(f64::INFINITY, f64::min);
    let mut high = hi.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    for &v in rest {
        low = low.min(v);
        high = high.max(v);
    }
    let first = |x: f64| series.iter().position(|&v| v == x).unwrap_or(0);
    (first(low), first(high))
}

/// The extremum of the series with harmonics `q` next to its sample `j` of `series`: `sense`
/// +1 for a maximum, -1 for a minimum. Newton on `q'(θ) = 0` from the vertex of the parabola
/// through the sample and its neighbours, kept within one sample spacing of the sample; the
/// sample's value if Newton does not improve on it.
fn refine_extremum(q: &[Complex64], series: &[f64], j: usize, sense: f64) -> f64 {
    let points = series.len();
    let step = std::f64::consts::TAU / points as f64;
    let theta = j as f64 * step;
    let at = series[j];
    let derivs = |t: f64| {
        let (mut v, mut d1, mut d2) = (0.0, 0.0, 0.0);
        // e^{ikt} by the recurrence e^{it} e^{i(k-1)t}: one sine and cosine per call.
        let step = Complex64::from_polar(1.0, t);
        let mut rot = Complex64::new(1.0, 0.0);
        for (k, qk) in q.iter().enumerate() {
            if k > 0 {
                rot *= step;
            }
            let z = qk * rot;
            let kf = k as f64;
            v += z.re;
            d1 -= kf * z.im;
            d2 -= kf * kf * z.re;
        }
        (v, d1, d2)
    };
    // The parabola's vertex: within half a spacing of the extremum's sample, a start
    // O(step³) from the extremum instead of O(step).
    let (before, after) = (series[(j + points - 1) % points], series[(j + 1) % points]);
    let curvature = before - 2.0 * at + after;
    let offset = 0.5 * (before - after) / curvature;
    let mut t = theta;
    if offset.is_finite() && offset.abs() <= 0.5 {
        t += offset * step;
    }
    for _ in 0..20 {
        let (_, d1, d2) = derivs(t);
        if d2 == 0.0 || !d1.is_finite() {
            break;
        }
        let next = (t - d1 / d2).clamp(theta - step, theta + step);
        // The value's error is about ½ q'' δθ²: a step of 1e-9 of the spacing leaves
        // 1e-18 of q'' step², below rounding; rounding in q'/q'' keeps Newton's steps
        // from falling much lower, so a tighter test would run all iterations.
        if (next - t).abs() <= 1e-9 * step {
            t = next;
            break;
        }
        t = next;
    }
    let (v, _, _) = derivs(t);
    if v.is_finite() && sense * (v - at) >= 0.0 {
        v
    } else {
        at
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One FFT plan for all DOFs gives the per-DOF extremes, and both find the analytic
    /// extremes of `q = a cos(θ - φ) + b cos(40 θ)` between the samples.
    #[test]
    fn extremes_of_all_dofs_equal_the_per_dof_extremes() {
        let (n, h) = (3, 40);
        let mut q = vec![Complex64::default(); (h + 1) * n];
        for dof in 0..n {
            let a = 1.0 + dof as f64;
            q[n + dof] = Complex64::from_polar(a, -0.3 * dof as f64 - 0.1234);
            q[h * n + dof] = Complex64::new(1e-3, 0.0);
            q[dof] = Complex64::new(0.5 * dof as f64, 0.0);
        }
        let basis = HarmonicBasis::new(2.0, h).unwrap();
        let names = (0..n).map(|i| format!("x{i}")).collect();
        let sol = Solution::from_harmonics(basis, names, q, 0.0).unwrap();
        let all = sol.extremes_all();
        for (dof, &(lo, hi)) in all.iter().enumerate() {
            let (l, u) = sol.extremes(dof);
            assert!((lo - l).abs() < 1e-13 && (hi - u).abs() < 1e-13, "{dof}");
            // The small 40th harmonic moves the extremes of mean ± a by at most its amplitude.
            let (mean, a) = (0.5 * dof as f64, 1.0 + dof as f64);
            assert!((hi - (mean + a)).abs() <= 1e-3 + 1e-12, "{dof}: {hi}");
            assert!((lo - (mean - a)).abs() <= 1e-3 + 1e-12, "{dof}: {lo}");
        }
        assert_eq!(sol.max_abs_all()[2], sol.max_abs(2));
    }
}
