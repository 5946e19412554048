//! The exact solution sampled over the period (`--out`'s time series).

use super::Waveform;
use crate::stability::expm::ExpWork;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

impl Waveform {
    /// `q_i(θ_j)`, `θ_j = 2π j / points` (`[i][j]`): per piece one exponential to its first
    /// sample and one step `e^{A_p δ}` between samples, without allocating per sample.
    pub(in crate::solve::piecewise) fn time_series(&self, points: usize) -> Vec<Vec<f64>> {
        let s = &self.schedule;
        let (n, omega) = (s.n, s.omega);
        let mut out = vec![vec![0.0; points]; n];
        if points == 0 {
            return out;
        }
        let spacing = TAU / points as f64;
        let mut work = ExpWork::new(2 * n);
        // One step e^{A_c δ} per configuration.
        let steps: Vec<DMatrix<f64>> = s
            .configurations
            .iter()
            .map(|c| {
                let mut step = DMatrix::zeros(2 * n, 2 * n);
                work.exp(&c.generator, spacing / omega, &mut step);
                step
            })
            .collect();
        let mut lead = DMatrix::zeros(2 * n, 2 * n);
        // Buffers: no allocation per sample.
        let mut steady = vec![0.0; n];
        let mut next = DVector::zeros(2 * n);
        // Pieces cover [θ_0, θ_0 + 2π): sample j' lies in piece p for
        // index(θ_p) <= j' < index(θ_{p+1}), the last piece ending at index(θ_0) + points so
        // that every sample j' mod points is written once, whatever the rounding.
        let index = |theta: f64| (theta / spacing).ceil() as usize;
        let first_index = index(s.pieces[0].start);
        let last = s.pieces.len() - 1;
        for (p, (piece, h)) in s.pieces.iter().zip(&self.free_start).enumerate() {
            let first = if p == 0 {
                first_index
            } else {
                index(piece.start)
            };
            let end = if p == last {
                first_index + points
            } else {
                index(piece.end)
            };
            if first >= end {
                continue;
            }
            let config = &s.configurations[piece.configuration];
            let theta = first as f64 * spacing;
            work.exp(&config.generator, (theta - piece.start) / omega, &mut lead);
            // The free motion in the scaled state `(q, q̇/ω_s)`: its first n rows are the
            // positions themselves.
            let mut scaled = &lead * s.scale_state(h.clone());
            for j in first..end {
                config.steady_positions_into(j as f64 * spacing, &mut steady);
                for (i, row) in out.iter_mut().enumerate() {
                    row[j % points] = steady[i] + scaled[i];
                }
                next.gemv(1.0, &steps[piece.configuration], &scaled, 0.0);
                std::mem::swap(&mut scaled, &mut next);
            }
        }
        out
    }
}
