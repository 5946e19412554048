//! Contact edges crossed between grid points, corrected line by line along each law's own
//! axis.
//!
//! A backlash law is only piecewise smooth in u. Sampled plainly, its trapezoid sums are off
//! by O(h²) wherever u crosses an edge between samples, and the residual has a kink wherever
//! a grid point crosses an edge, which stalls Newton where a contact opens (docs/torus.md).
//! Along one grid line of the element's base b (the other angles fixed) the coordinate is a
//! trigonometric polynomial of θ_b,
//!
//! `u(θ_b) = Re Σ_{m ≤ H_b} C_m e^{i m θ_b}` (`C_m` the line's own DFT),
//!
//! so the one-frequency machinery of [`crate::harmonic::kinks`] applies on the line: the
//! crossings θ* of every kink κ by Newton on the series, the jumps of f and of its derivatives
//! there (with u̇ from its own series along the line, since the other bases turn too) and the
//! Euler–Maclaurin error of the trapezoid rule, subtracted from the line's harmonics
//! `m ≤ M = min(H_b + 1, ⌊(N_b - 1)/2⌋)` (the first harmonic beyond the cap is what the
//! truncation estimate reads). The correction is written back as samples,
//! `δf_j = Re Σ_{m ≤ M} δC_m e^{i m θ_j}`: band-limited below `N_b/2`, so the grid's transform
//! of the corrected samples holds the corrected line spectrum in every line of the index set.
//! The samples of `∂f/∂u`, `∂f/∂u̇` are corrected the same way on the bins
//! `m ≤ min(2H_b, ⌊(N_b - 1)/2⌋)`, so the Jacobian is the derivative of the exact integral.
//!
//! What is left is the trapezoid rule of the other axes over the line integrals, which are
//! smooth in those angles except where a line grazes an edge (a contact about to open).

use super::elements::TorusElement;
use super::{TorusBalance, TorusWorkspace};
use crate::force::ForceLaw;
use crate::harmonic::kinks::{self, Crossing, EdgeCrossing, OrbitAt};
use num_complex::Complex64;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::f64::consts::TAU;
use std::sync::Arc;

/// The real FFTs of one grid line along each base.
#[derive(Clone)]
pub(super) struct LinePlans {
    forward: Vec<Arc<dyn RealToComplex<f64>>>,
    inverse: Vec<Arc<dyn ComplexToReal<f64>>>,
}

impl std::fmt::Debug for LinePlans {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinePlans")
            .field(
                "lengths",
                &self.forward.iter().map(|p| p.len()).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl LinePlans {
    /// Plans for a grid of `dims`.
    pub(super) fn new(dims: &[usize]) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        Self {
            forward: dims.iter().map(|&n| planner.plan_fft_forward(n)).collect(),
            inverse: dims.iter().map(|&n| planner.plan_fft_inverse(n)).collect(),
        }
    }

    /// Buffers for these plans and `coordinates` element coordinates.
    pub(super) fn buffers(&self, coordinates: usize) -> EdgeBuffers {
        let n = self.forward.iter().map(|p| p.len()).max().unwrap_or(0);
        let scratch = self
            .forward
            .iter()
            .map(|p| p.get_scratch_len())
            .chain(self.inverse.iter().map(|p| p.get_scratch_len()))
            .max()
            .unwrap_or(0);
        let spectrum = || vec![Complex64::default(); n / 2 + 1];
        EdgeBuffers {
            reach: vec![0.0; coordinates * self.forward.len()],
            u: vec![0.0; n],
            slope: vec![0.0; n],
            work: vec![0.0; n],
            uk: spectrum(),
            vk: spectrum(),
            spec: spectrum(),
            scratch: vec![Complex64::default(); scratch],
            edges: Vec::new(),
            line: Vec::new(),
            starts: Vec::new(),
            found: Vec::new(),
        }
    }
}

/// Buffers of the edge correction (part of [`TorusWorkspace`]).
#[derive(Debug, Clone)]
pub(super) struct EdgeBuffers {
    /// Per coordinate c and base b (at `c d + b`): `h_b Σ_j |k_{j,b}| |U_{j,c}|`, the most u_c
    /// moves between two samples along base b.
    reach: Vec<f64>,
    u: Vec<f64>,
    slope: Vec<f64>,
    work: Vec<f64>,
    uk: Vec<Complex64>,
    vk: Vec<Complex64>,
    spec: Vec<Complex64>,
    scratch: Vec<Complex64>,
    edges: Vec<EdgeCrossing>,
    line: Vec<Crossing>,
    /// The crossings of the element corrected last, and the first grid point of each one's
    /// line (for the derivative samples).
    starts: Vec<usize>,
    found: Vec<Crossing>,
}

impl TorusBalance<'_> {
    /// Notes how far coordinate `c` of `u` moves at most between two samples along each base.
    pub(super) fn note_reach(&self, u: &[Complex64], c: usize, ws: &mut TorusWorkspace) {
        let (m, d) = (self.coordinates(), self.set.dims());
        for b in 0..d {
            let h = TAU / self.fft.dims()[b] as f64;
            let slope: f64 = (0..self.set.len())
                .map(|j| f64::from(self.set.k(j)[b].unsigned_abs()) * u[j * m + c].norm())
                .sum();
            ws.edges.reach[c * d + b] = h * slope;
        }
    }

    /// Corrects the force samples `ws.fe` of `act` (its law `law`) at every crossing of a
    /// kink along the grid lines of its base, and keeps the crossings for
    /// [`correct_edge_derivatives`](Self::correct_edge_derivatives).
    pub(super) fn correct_edge_forces(
        &self,
        act: &TorusElement,
        law: &dyn ForceLaw,
        ws: &mut TorusWorkspace,
    ) {
        let TorusWorkspace {
            ue, due, fe, edges, ..
        } = ws;
        edges.starts.clear();
        edges.found.clear();
        if act.kinks.is_empty() {
            return;
        }
        let b = act.base;
        let (n, stride) = self.axis(b);
        let reach = act.factor.abs() * edges.reach[act.coordinate * self.set.dims() + b];
        for o in 0..self.fft.points() / (n * stride) {
            for i in 0..stride {
                let start = o * n * stride + i;
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for (j, x) in edges.u[..n].iter_mut().enumerate() {
                    *x = ue[start + j * stride];
                    (lo, hi) = (lo.min(*x), hi.max(*x));
                }
                if !act
                    .kinks
                    .iter()
                    .any(|&k| k >= lo - reach && k <= hi + reach)
                {
                    continue;
                }
                let line = |j: usize| start + j * stride;
                self.line_crossings(act, law, edges, |j| due[line(j)]);
                if edges.line.is_empty() {
                    continue;
                }
                // δf_j = Re Σ_{m ≤ M} δC_m e^{i m θ_j}: half spectrum Y_0 = δC_0, Y_m = δC_m / 2,
                // up to the first harmonic beyond the cap (the truncation estimate reads it).
                let top = (self.set.caps()[b] + 1).min((n - 1) / 2);
                edges.spec.fill(Complex64::default());
                kinks::correct_harmonics(&mut edges.spec[..=top], n, &edges.line);
                for y in &mut edges.spec[1..=top] {
                    *y *= 0.5;
                }
                self.add_line_correction(b, start, fe, edges);
                edges
                    .starts
                    .extend(std::iter::repeat_n(start, edges.line.len()));
                edges.found.append(&mut edges.line);
            }
        }
    }

    /// Corrects the derivative samples `ws.ge`, `ws.gde` of `act` at the crossings
    /// [`correct_edge_forces`](Self::correct_edge_forces) found.
    pub(super) fn correct_edge_derivatives(&self, act: &TorusElement, ws: &mut TorusWorkspace) {
        let TorusWorkspace { ge, gde, edges, .. } = ws;
        let n = self.fft.dims()[act.base];
        // Below the Nyquist bin of an even grid; every bin of an odd one.
        let bins = (2 * self.set.caps()[act.base]).min((n - 1) / 2);
        let mut first = 0;
        while first < edges.found.len() {
            let start = edges.starts[first];
            let last = first
                + edges.starts[first..]
                    .iter()
                    .take_while(|&&s| s == start)
                    .count();
            for (of_velocity, samples) in [(false, &mut *ge), (true, &mut *gde)] {
                // g_j = ĝ_0 + 2 Re Σ_m ĝ_m e^{i m θ_j}: half spectrum Y_m = δĝ_m.
                edges.spec.fill(Complex64::default());
                let crossings = &edges.found[first..last];
                kinks::correct_spectrum(&mut edges.spec[..=bins], n, crossings, of_velocity);
                self.add_line_correction(act.base, start, samples, edges);
            }
            first = last;
        }
    }

    /// The crossings of `act`'s kinks by the line in `edges.u` (rate at sample j: `rate(j)`)
    /// with their jumps, into `edges.line`.
    fn line_crossings(
        &self,
        act: &TorusElement,
        law: &dyn ForceLaw,
        edges: &mut EdgeBuffers,
        rate: impl Fn(usize) -> f64,
    ) {
        let b = act.base;
        let n = self.fft.dims()[b];
        let cap = self.set.caps()[b];
        let (forward, inverse) = (&self.line_plans.forward[b], &self.line_plans.inverse[b]);
        // The line's series `C_m` of u (then of u̇) from the samples in `work`, its transform
        // left in `spec`.
        let series = |work: &mut [f64], spec: &mut [Complex64], scratch: &mut [_], c: &mut [_]| {
            let _ = forward.process_with_scratch(work, spec, scratch);
            // u = Re Σ C_m e^{i m θ}: C_0 = X_0/n, C_m = 2 X_m/n.
            for (m, c) in c.iter_mut().enumerate() {
                *c = spec[m] * if m == 0 { 1.0 } else { 2.0 } / n as f64;
            }
        };
        edges.work[..n].copy_from_slice(&edges.u[..n]);
        let spec = &mut edges.spec[..n / 2 + 1];
        let uk = &mut edges.uk[..=cap];
        series(&mut edges.work[..n], spec, &mut edges.scratch, uk);
        // The slope u' = ∂u/∂θ_b at the samples.
        for (m, y) in spec.iter_mut().enumerate() {
            *y = if m <= cap && m > 0 {
                *y * Complex64::new(0.0, m as f64 / n as f64)
            } else {
                Complex64::default()
            };
        }
        let _ = inverse.process_with_scratch(spec, &mut edges.slope[..n], &mut edges.scratch);
        for (j, x) in edges.work[..n].iter_mut().enumerate() {
            *x = rate(j);
        }
        let vk = &mut edges.vk[..=cap];
        series(&mut edges.work[..n], spec, &mut edges.scratch, vk);
        edges.edges.clear();
        edges.line.clear();
        let (uk, vk) = (&edges.uk[..=cap], &edges.vk[..=cap]);
        let (u, slope) = (&edges.u[..n], &edges.slope[..n]);
        kinks::find_edge_crossings(&act.kinks, u, slope, uk, 1.0, &mut edges.edges);
        let h = TAU / n as f64;
        for e in &edges.edges {
            let v = kinks::derivatives(vk, e.theta);
            let orbit = OrbitAt {
                theta: e.theta,
                alpha: ((e.theta - e.sample as f64 * h) / h).clamp(0.0, 1.0),
                u: kinks::derivatives(uk, e.theta),
                v: [v[0], v[1], v[2]],
            };
            let angle = |t: f64| t.rem_euclid(TAU);
            edges
                .line
                .extend(kinks::jumps(law, e.kappa, &orbit, angle, h));
        }
    }

    /// Adds the samples of the half spectrum in `edges.spec` (a real line: the mean's
    /// imaginary part and the Nyquist bin dropped; unnormalised inverse) to the grid line of
    /// base b from grid point `start` in `samples`.
    fn add_line_correction(
        &self,
        b: usize,
        start: usize,
        samples: &mut [f64],
        edges: &mut EdgeBuffers,
    ) {
        let (n, stride) = self.axis(b);
        let spec = &mut edges.spec[..n / 2 + 1];
        spec[0].im = 0.0;
        if n % 2 == 0 {
            spec[n / 2] = Complex64::default();
        }
        let inverse = &self.line_plans.inverse[b];
        let _ = inverse.process_with_scratch(spec, &mut edges.work[..n], &mut edges.scratch);
        for (j, w) in edges.work[..n].iter().enumerate() {
            samples[start + j * stride] += w;
        }
    }
}
