//! The harmonic balance on the torus, condensed onto the element coordinates:
//!
//! `R_j(U) = G_j⁻¹ U_j + N_j(U) - L_j = 0` for every line j of the index set, with the rest
//! `N(U)` of the elements' forces by AFT on the torus grid: per coordinate c,
//! `u_c(θ) = Re Σ_j U_{j,c} e^{i k_j·θ}` and `u̇_c = Re Σ_j i ν_j U_{j,c} e^{i k_j·θ}`
//! (`ν_j = Ω k_j·r`), each element's `f(θ_b, s u_c, s u̇_c) - f0 - k0 u - d0 u̇` evaluated at its
//! own base's angle, summed per coordinate (times `s`) and transformed back.
//!
//! The Jacobian is applied, not stored: `J v = G⁻¹ v + FFT[g_u v(θ) + g_u̇ v̇(θ)]` with the
//! samples `g = Σ_e s² (∂f/∂u - k0)` of the last evaluation (the exact derivative of the AFT),
//! for the Krylov solver of [`super::newton_krylov`].

use super::elements::{active_elements, full_load, TorusElement};
use super::grid::{TorusFft, TorusScratch};
use super::linear::TorusLinear;
use super::{IndexSet, TorusModel};
use crate::error::{Error, Result};
use nalgebra::DMatrix;
use num_complex::Complex64;
use std::f64::consts::TAU;

/// The torus harmonic balance of a [`TorusModel`] on an index set and grid, at speed Ω.
#[derive(Debug)]
pub struct TorusBalance<'m> {
    pub(super) tm: TorusModel<'m>,
    pub(super) set: IndexSet,
    pub(super) fft: TorusFft,
    omega: f64,
    coordinates: Vec<Vec<(usize, f64)>>,
    names: Vec<String>,
    pub(super) active: Vec<TorusElement>,
    /// Per base, its `N_b` sample angles `2π j / N_b` (one grid line along it).
    pub(super) line_thetas: Vec<Vec<f64>>,
    pub(super) dense: crate::model::DenseMatrices,
    pub(super) augmentation: Option<DMatrix<f64>>,
    /// The rigid-body modes of a free-free model, whose mean loads must balance at every speed.
    rigid: Option<crate::model::RigidModes>,
    pub(super) w: DMatrix<f64>,
    f_full: Vec<Complex64>,
    pub(super) linear: TorusLinear,
    pub(super) line_plans: super::edges::LinePlans,
}

/// Buffers of [`TorusBalance`]; make one with [`TorusBalance::workspace`].
#[derive(Debug, Clone)]
pub struct TorusWorkspace {
    pub(super) fft: TorusScratch,
    pub(super) u: Vec<Vec<f64>>,
    pub(super) du: Vec<Vec<f64>>,
    pub(super) force: Vec<Vec<f64>>,
    pub(super) ue: Vec<f64>,
    pub(super) due: Vec<f64>,
    pub(super) fe: Vec<f64>,
    pub(super) ge: Vec<f64>,
    pub(super) gde: Vec<f64>,
    /// `Σ_e s² (∂f/∂u - k0)`, `Σ_e s² (∂f/∂u̇ - d0)` per coordinate at the last evaluation
    /// with derivatives.
    pub(super) gu: Vec<Vec<f64>>,
    pub(super) gdu: Vec<Vec<f64>>,
    /// One grid line along a base: `u`, `u̇` and the law's values there.
    pub(super) lines: [Vec<f64>; 4],
    /// The contact edges' correction.
    pub(super) edges: super::edges::EdgeBuffers,
    /// One line's m coordinates (the receptance form's `G_j x_j`).
    line: Vec<Complex64>,
    /// Transforms done.
    pub ffts: usize,
}

impl<'m> TorusBalance<'m> {
    /// The balance of `tm` on `set` with `samples` grid points per base at speed `omega`
    /// (rad/s of the speed the bases' ratios refer to). Errors, before any work: a load or an
    /// element's time variation above its base's cap, a law with memory, a grid too coarse or
    /// too large, a singular dynamic stiffness at some line, static loads that do not balance
    /// on a free-free model.
    pub fn new(tm: TorusModel<'m>, set: IndexSet, samples: &[usize], omega: f64) -> Result<Self> {
        let model = tm.model();
        if set.base_ratios() != tm.bases().ratios() {
            return Err(Error::InvalidElement {
                context: "torus index set".into(),
                reason: format!(
                    "it was built for bases with ratios {:?}, the model's bases have {:?}",
                    set.base_ratios(),
                    tm.bases().ratios()
                ),
            });
        }
        crate::harmonic::HarmonicBasis::new(omega, 0)?;
        model.check_load_speeds(omega, omega)?;
        let fft = TorusFft::new(&set, samples)?;
        let n = model.n_dofs();
        let f_full = full_load(&tm, &set, omega)?;
        let (active, coordinates, names) = active_elements(&tm, &set, fft.dims())?;
        let line_thetas = fft
            .dims()
            .iter()
            .map(|&nb| (0..nb).map(|j| TAU * j as f64 / nb as f64).collect())
            .collect();
        let line_plans = super::edges::LinePlans::new(fft.dims());
        let dense = model.dense("torus harmonic balance")?;
        let w = DMatrix::from_fn(n, coordinates.len(), |i, c| {
            coordinates[c]
                .iter()
                .filter(|(k, _)| *k == i)
                .map(|(_, v)| v)
                .sum()
        });
        let (mut augmentation, mut rigid_modes) = (None, None);
        let linear = match TorusLinear::new(&dense, None, &set, omega, &w, &f_full) {
            Err(e @ Error::SingularDynamicStiffness { harmonic: 0, .. }) => {
                let rigid = crate::model::rigid::find_dense(model, &dense).ok_or(e)?;
                let mean: Vec<f64> = f_full[..n].iter().map(|v| v.re).collect();
                rigid.check_balance(model, &mean)?;
                let a = rigid.augmentation();
                let linear = TorusLinear::new(&dense, Some(&a), &set, omega, &w, &f_full)?;
                augmentation = Some(a);
                rigid_modes = Some(rigid);
                linear
            }
            r => r?,
        };
        Ok(Self {
            tm,
            set,
            fft,
            omega,
            coordinates,
            names,
            active,
            line_thetas,
            dense,
            augmentation,
            rigid: rigid_modes,
            w,
            f_full,
            linear,
            line_plans,
        })
    }

    /// Moves the balance to speed `omega` (refactors every line); nothing changes on an error.
    pub fn set_omega(&mut self, omega: f64) -> Result<()> {
        crate::harmonic::HarmonicBasis::new(omega, 0)?;
        self.tm.model().check_load_speeds(omega, omega)?;
        let f_full = full_load(&self.tm, &self.set, omega)?;
        if let Some(rigid) = &self.rigid {
            // A static load over speed may stop balancing: no periodic solution there.
            let n = self.tm.model().n_dofs();
            let mean: Vec<f64> = f_full[..n].iter().map(|v| v.re).collect();
            rigid.check_balance(self.tm.model(), &mean)?;
        }
        let aug = self.augmentation.as_ref();
        self.linear = TorusLinear::new(&self.dense, aug, &self.set, omega, &self.w, &f_full)?;
        self.f_full = f_full;
        self.omega = omega;
        Ok(())
    }

    /// Buffers for this balance.
    pub fn workspace(&self) -> TorusWorkspace {
        let (p, m) = (self.fft.points(), self.coordinates.len());
        let grid = || vec![0.0; p];
        TorusWorkspace {
            fft: self.fft.make_scratch(),
            u: vec![grid(); m],
            du: vec![grid(); m],
            force: vec![grid(); m],
            ue: grid(),
            due: grid(),
            fe: grid(),
            ge: grid(),
            gde: grid(),
            gu: vec![grid(); m],
            gdu: vec![grid(); m],
            lines: std::array::from_fn(|_| {
                vec![0.0; self.fft.dims().iter().copied().max().unwrap_or(0)]
            }),
            line: vec![Complex64::default(); m],
            edges: self.line_plans.buffers(m),
            ffts: 0,
        }
    }

    /// The speed Ω.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The index set.
    pub fn set(&self) -> &IndexSet {
        &self.set
    }

    /// The model on its bases.
    pub fn torus_model(&self) -> &TorusModel<'m> {
        &self.tm
    }

    /// The grid's samples per base.
    pub fn samples(&self) -> &[usize] {
        self.fft.dims()
    }

    /// Number of element coordinates m (unknowns per line).
    pub fn coordinates(&self) -> usize {
        self.coordinates.len()
    }

    /// The coordinates' names (`u(element)`).
    pub fn coordinate_names(&self) -> &[String] {
        &self.names
    }

    /// Number of complex unknowns (lines × coordinates).
    pub fn len(&self) -> usize {
        self.set.len() * self.coordinates.len()
    }

    /// `true` where nothing is condensed (no time-varying or nonlinear element): the
    /// response is `Z_j⁻¹ F_j`.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The frequency `ν_j = Ω k_j·r` of line j (rad/s).
    pub fn frequency(&self, j: usize) -> f64 {
        self.omega * self.set.ratio(j)
    }

    /// The condensed load `L` (line-major).
    pub fn load(&self) -> &[Complex64] {
        &self.linear.load
    }

    /// The linear start: `U_j = G_j L_j` (the response with the rest `N = 0`).
    pub fn linear_start(&self) -> Vec<Complex64> {
        let m = self.coordinates();
        let mut u = Vec::with_capacity(self.len());
        for x in &self.linear.solved {
            for c in 0..m {
                u.push(
                    self.coordinates[c]
                        .iter()
                        .map(|&(i, w)| x[(i, m)] * w)
                        .sum(),
                );
            }
        }
        u
    }

    /// `out ← R(U) = G⁻¹ U + N(U) - L` (in the receptance form of dependent coordinates
    /// `R(U) = U + G N(U) − G L`); with `derivatives`, the samples the Jacobian needs are
    /// kept in `ws`.
    pub fn residual_into(
        &self,
        u: &[Complex64],
        out: &mut [Complex64],
        derivatives: bool,
        ws: &mut TorusWorkspace,
    ) -> Result<()> {
        self.rest_into(u, out, derivatives, ws)?;
        let m = self.coordinates();
        if self.linear.receptance_form {
            self.times_receptance_plus(u, out, ws);
            for (o, l) in out.iter_mut().zip(&self.linear.load) {
                *o -= l;
            }
            return Ok(());
        }
        for (j, g) in self.linear.stiffness.iter().enumerate() {
            let x = &u[j * m..(j + 1) * m];
            for (a, o) in out[j * m..(j + 1) * m].iter_mut().enumerate() {
                let lin: Complex64 = x.iter().enumerate().map(|(b, v)| g[(a, b)] * v).sum();
                *o += lin - self.linear.load[j * m + a];
            }
        }
        Ok(())
    }

    /// `out ← N(U)`, the rest of the elements' forces per line and coordinate.
    pub fn rest_into(
        &self,
        u: &[Complex64],
        out: &mut [Complex64],
        derivatives: bool,
        ws: &mut TorusWorkspace,
    ) -> Result<()> {
        let m = self.coordinates();
        self.force_samples(u, derivatives, ws)?;
        out.fill(Complex64::default());
        for c in 0..m {
            let mut force = std::mem::take(&mut ws.force[c]);
            self.fft
                .analyze(&mut force, &mut ws.fft, |j, v| out[j * m + c] = v);
            ws.force[c] = force;
            ws.ffts += 1;
        }
        Ok(())
    }

    /// Samples of coordinate c of `u` (or of its time derivative) into `out`.
    pub(super) fn synthesize(
        &self,
        u: &[Complex64],
        c: usize,
        derivative: bool,
        out: &mut [f64],
        scratch: &mut TorusScratch,
    ) {
        let m = self.coordinates();
        let omega = self.omega;
        let set = &self.set;
        if derivative {
            self.fft.synthesize_into(
                |j| u[j * m + c] * Complex64::new(0.0, omega * set.ratio(j)),
                out,
                scratch,
            );
        } else {
            self.fft.synthesize_into(|j| u[j * m + c], out, scratch);
        }
    }

    /// `out ← J v = G⁻¹ v + ∂N/∂U v` at the state of the last
    /// [`residual_into`](Self::residual_into) with derivatives.
    pub fn jacobian_apply(&self, v: &[Complex64], out: &mut [Complex64], ws: &mut TorusWorkspace) {
        let m = self.coordinates();
        if self.linear.receptance_form {
            out.fill(Complex64::default());
        } else {
            self.linear.apply_stiffness(v, out);
        }
        for c in 0..m {
            let (mut x, mut dx) = (std::mem::take(&mut ws.ue), std::mem::take(&mut ws.due));
            self.synthesize(v, c, false, &mut x, &mut ws.fft);
            self.synthesize(v, c, true, &mut dx, &mut ws.fft);
            ws.ffts += 2;
            for (p, xp) in x.iter_mut().enumerate() {
                *xp = ws.gu[c][p] * *xp + ws.gdu[c][p] * dx[p];
            }
            self.fft
                .analyze(&mut x, &mut ws.fft, |j, val| out[j * m + c] += val);
            ws.ffts += 1;
            (ws.ue, ws.due) = (x, dx);
        }
        if self.linear.receptance_form {
            self.times_receptance_plus(v, out, ws);
        }
    }

    /// The grid means of the derivative samples per coordinate, `(ḡ_u, ḡ_u̇)`, at the last
    /// evaluation with derivatives: the averaged Jacobian's diagonal.
    pub(super) fn mean_derivatives(&self, ws: &TorusWorkspace) -> Vec<(f64, f64)> {
        let p = self.fft.points() as f64;
        (0..self.coordinates())
            .map(|c| {
                (
                    ws.gu[c].iter().sum::<f64>() / p,
                    ws.gdu[c].iter().sum::<f64>() / p,
                )
            })
            .collect()
    }

    /// `out_j ← x_j + G_j out_j` line by line (the receptance form).
    fn times_receptance_plus(
        &self,
        x: &[Complex64],
        out: &mut [Complex64],
        ws: &mut TorusWorkspace,
    ) {
        let m = self.coordinates();
        for (j, g) in self.linear.receptance.iter().enumerate() {
            let o = &mut out[j * m..(j + 1) * m];
            for a in 0..m {
                ws.line[a] = x[j * m + a] + (0..m).map(|b| g[(a, b)] * o[b]).sum::<Complex64>();
            }
            o.copy_from_slice(&ws.line);
        }
    }

    /// Whether the balance is in the receptance form `U + G N(U) − G L = 0` (the element
    /// coordinates are linearly dependent, as a planetary set's meshes are).
    pub fn receptance_form(&self) -> bool {
        self.linear.receptance_form
    }

    /// The full response `Q_j` (line-major, n DOFs per line) of the unknowns `u`.
    pub fn full_harmonics(
        &self,
        u: &[Complex64],
        ws: &mut TorusWorkspace,
    ) -> Result<Vec<Complex64>> {
        let mut rest = vec![Complex64::default(); self.len()];
        if !self.is_empty() {
            self.rest_into(u, &mut rest, false, ws)?;
        }
        Ok(self.linear.recover(&rest))
    }

    /// The full load `F_j` (line-major, n per line), with the elements' static offsets moved
    /// to the load side.
    pub fn full_load(&self) -> &[Complex64] {
        &self.f_full
    }
}
