//! Frequency sweeps: a warm-started sweep and pseudo-arclength continuation through turning
//! points, with the stability of every point.
//!
//! Continuation follows the branch `R(x, Ω) = 0` in the scaled unknowns `y = (x/s_x, Ω/s_Ω)`.
//! Predictor: `y_p = y_i + s t_i` along the unit tangent. Corrector: Newton on the bordered
//! system
//!
//! `[[R_x s_x, R_Ω s_Ω], [t_iᵀ]] δ = -[R, t_iᵀ (y - y_p)]`,
//!
//! with the exact AFT Jacobian `R_x` and the analytic `R_Ω`
//! ([`HarmonicBalance::omega_derivative_real_into`]). The new tangent solves the same matrix
//! with right-hand side `(0, 1)`, which keeps its orientation. A turning point (fold) lies where
//! the Ω-component of the tangent changes sign. The step grows by 1.5 after quick corrector
//! convergence, shrinks by 0.5 after a failure, and the branch stops with a reason (and all
//! points so far) when it falls under its minimum.

use crate::error::{Error, Result};
use crate::harmonic::RealLayout;
use crate::model::Model;
use crate::residual::{HarmonicBalance, Workspace};
use crate::solve::lu;
use crate::solve::Newton;
use crate::stability::{Bifurcation, Floquet, FloquetOptions};
use crate::HarmonicBasis;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// One periodic solution on a branch.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct BranchPoint {
    /// The swept parameter (Ω itself for a frequency sweep).
    pub parameter: f64,
    /// Fundamental Ω (rad/s).
    pub omega: f64,
    /// Harmonics, harmonic-major (`Q[k * n + i]`).
    pub harmonics: Vec<Complex64>,
    /// `max |q_i|` over one period per DOF.
    pub max_abs: Vec<f64>,
    /// Relative residual.
    pub residual: f64,
    /// Truncation estimate of the point ([`Solution::truncation_estimate`](crate::Solution::truncation_estimate)).
    #[serde(default)]
    pub truncation: f64,
    /// Floquet multipliers, if computed.
    pub floquet: Option<Floquet>,
    /// A turning point of the branch lies between the previous point and this one.
    pub fold: bool,
    /// Its Ω, interpolated from the tangents at both points (Ω'(s) linear in arclength).
    pub fold_omega: Option<f64>,
    /// Stability changed between the previous point and this one, with this kind of
    /// critical multiplier.
    pub bifurcation: Option<Bifurcation>,
}

impl BranchPoint {
    /// `Some(true)` if stable, `None` if not computed.
    pub fn stable(&self) -> Option<bool> {
        self.floquet.as_ref().map(|f| f.is_stable())
    }
}

/// Why a branch ended.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BranchStop {
    /// The end of the parameter range was reached.
    Reached,
    /// The point limit was reached.
    MaxPoints,
    /// The step fell under its minimum near this Ω.
    StepTooSmall {
        /// Where the branch got stuck.
        omega: f64,
    },
    /// The bordered (or Newton) matrix was singular.
    Singular {
        /// Where.
        omega: f64,
    },
    /// Newton did not converge at this parameter value (a parameter sweep does not follow
    /// folds: use a frequency sweep there).
    NotConverged {
        /// The parameter value.
        parameter: f64,
    },
    /// The scene could not be built at this parameter value (e.g. a negative stiffness).
    InvalidParameter {
        /// The parameter value.
        parameter: f64,
        /// What is wrong.
        reason: String,
    },
    /// The first point did not converge.
    StartFailed {
        /// The solver's termination.
        reason: String,
    },
}

impl std::fmt::Display for BranchStop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BranchStop::Reached => write!(f, "end of range reached"),
            BranchStop::MaxPoints => write!(f, "point limit reached"),
            BranchStop::StepTooSmall { omega } => {
                write!(f, "step size under its minimum near Ω = {omega}")
            }
            BranchStop::Singular { omega } => {
                write!(f, "singular bordered system near Ω = {omega}")
            }
            BranchStop::StartFailed { reason } => {
                write!(f, "first point did not converge: {reason}")
            }
            BranchStop::InvalidParameter { parameter, reason } => {
                write!(f, "invalid scene at parameter {parameter}: {reason}")
            }
            BranchStop::NotConverged { parameter } => {
                write!(
                    f,
                    "no convergence at parameter {parameter} (a fold in the parameter?)"
                )
            }
        }
    }
}

/// A computed branch.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Branch {
    /// DOF names.
    pub dofs: Vec<String>,
    /// H.
    pub harmonics: usize,
    /// The points in branch order.
    pub points: Vec<BranchPoint>,
    /// Why it ended.
    pub stop: BranchStop,
}

impl Branch {
    /// Number of turning points.
    pub fn folds(&self) -> usize {
        self.points.iter().filter(|p| p.fold).count()
    }
}

/// Pseudo-arclength continuation in Ω.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Continuation {
    /// Initial step in the scaled unknowns. Default 0.05.
    pub initial_step: f64,
    /// Smallest step before giving up. Default 1e-7.
    pub min_step: f64,
    /// Largest step. Default 1.0.
    pub max_step: f64,
    /// Point limit. Default 10 000.
    pub max_points: usize,
    /// Relative residual tolerance of the corrector. Default 1e-10.
    pub tolerance: f64,
    /// Corrector iterations before the step is halved. Default 8.
    pub max_corrector: usize,
    /// How to compute the stability of every point (`None`: no stability). Default: the
    /// default [`FloquetOptions`].
    pub stability: Option<FloquetOptions>,
}

impl Default for Continuation {
    fn default() -> Self {
        Self {
            initial_step: 0.05,
            min_step: 1e-7,
            max_step: 1.0,
            max_points: 10_000,
            tolerance: 1e-10,
            max_corrector: 8,
            stability: Some(FloquetOptions::default()),
        }
    }
}

/// Buffers of the corrector.
struct Bordered {
    layout: RealLayout,
    r: Vec<f64>,
    r_omega: Vec<f64>,
    jac: DMatrix<f64>,
    big: DMatrix<f64>,
    perm: Vec<usize>,
    rhs: Vec<f64>,
}

impl Bordered {
    fn new(layout: RealLayout) -> Self {
        let m = layout.len();
        Self {
            layout,
            r: vec![0.0; m],
            r_omega: vec![0.0; m],
            jac: DMatrix::zeros(m, m),
            big: DMatrix::zeros(m + 1, m + 1),
            perm: vec![0; m + 1],
            rhs: vec![0.0; m + 1],
        }
    }

    /// Evaluates R, R_x, R_Ω at (x, Ω) and factors the bordered matrix with last row `t`.
    /// Returns the relative residual, or None if singular.
    #[allow(clippy::too_many_arguments)]
    fn factor(
        &mut self,
        hb: &mut HarmonicBalance,
        ws: &mut Workspace,
        x: &[f64],
        omega: f64,
        t: &[f64],
        sx: f64,
        so: f64,
        ext: f64,
    ) -> Result<Option<f64>> {
        if (hb.basis().omega() - omega).abs() > 0.0 {
            hb.set_omega(omega)?;
        }
        hb.residual_real_into(x, &mut self.r, Some(&mut self.jac), ws)?;
        hb.omega_derivative_real_into(x, &mut self.r_omega, ws)?;
        let m = self.layout.len();
        for (j, tj) in t.iter().enumerate().take(m) {
            for i in 0..m {
                self.big[(i, j)] = self.jac[(i, j)] * sx;
            }
            self.big[(m, j)] = *tj;
        }
        for i in 0..m {
            self.big[(i, m)] = self.r_omega[i] * so;
        }
        self.big[(m, m)] = t[m];
        let rel = self.layout.norm(&self.r) / ext;
        if !rel.is_finite() {
            return Err(Error::NonFinite {
                what: "residual on the branch".into(),
            });
        }
        Ok(lu::factor_in_place(&mut self.big, &mut self.perm).then_some(rel))
    }
}

impl Continuation {
    /// Defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// Follows the branch of `model` from `basis.omega()` towards `to` (either direction),
    /// calling `progress` with the fraction of the range covered.
    pub fn run(
        &self,
        model: &Model,
        basis: HarmonicBasis,
        to: f64,
        mut progress: impl FnMut(f64),
    ) -> Result<Branch> {
        crate::error::check_positive("continuation", "to", to)?;
        let from = basis.omega();
        let mut hb = HarmonicBalance::new(model, basis)?;
        crate::solve::check_dense_for_continuation(&hb)?;
        let mut ws = hb.workspace();
        let layout = hb.layout();
        let m = layout.len();
        let mut branch = Branch {
            dofs: model.dof_names().to_vec(),
            harmonics: basis.harmonics(),
            points: Vec::new(),
            stop: BranchStop::Reached,
        };
        let start = Newton::new()
            .with_tolerance(self.tolerance)?
            .solve(&hb, &mut ws)?;
        if !start.is_converged() {
            branch.stop = BranchStop::StartFailed {
                reason: start.termination.to_string(),
            };
            return Ok(branch);
        }
        // Residuals relative to the load (or the load of the split, or 1 without either).
        let ext = [hb.norm(hb.external_load()), hb.norm(hb.split_load()), 1.0]
            .into_iter()
            .find(|v| *v > 0.0)
            .unwrap_or(1.0);
        let mut x = vec![0.0; m];
        layout.pack(start.harmonics(), &mut x);
        let sx = (layout.norm(&x) / (m as f64).sqrt()).max(1e-12 * ext.max(1.0));
        let so = from;
        let direction = if to >= from { 1.0 } else { -1.0 };
        let mut bordered = Bordered::new(layout);
        // Initial tangent from R_x dx = -R_Ω: t ∝ (dx/dΩ · s_Ω/s_x, 1).
        let mut t = vec![0.0; m + 1];
        t[m] = 1.0;
        match bordered.factor(&mut hb, &mut ws, &x, from, &t, sx, so, ext)? {
            Some(_) => {}
            None => {
                branch.stop = BranchStop::Singular { omega: from };
                return Ok(branch);
            }
        }
        self.tangent(&mut bordered, &mut t);
        if t[m] * direction < 0.0 {
            t.iter_mut().for_each(|v| *v = -*v);
        }
        let mut omega = from;
        self.push_point(&mut branch, model, &hb, &x, omega, start.residual(), false)?;
        let mut step = self.initial_step;
        let (mut xp, mut x_new) = (vec![0.0; m], vec![0.0; m]);
        while branch.points.len() < self.max_points {
            // Predictor.
            for i in 0..m {
                xp[i] = x[i] + step * t[i] * sx;
            }
            let op = omega + step * t[m] * so;
            x_new.copy_from_slice(&xp);
            let mut o_new = op;
            let mut converged = None;
            for it in 0..self.max_corrector {
                if o_new <= 0.0 {
                    break;
                }
                let rel = match bordered.factor(&mut hb, &mut ws, &x_new, o_new, &t, sx, so, ext) {
                    Ok(Some(rel)) => rel,
                    Ok(None) | Err(_) => break,
                };
                if rel <= self.tolerance {
                    converged = Some((it, rel));
                    break;
                }
                // δ from [R; tᵀ(y - y_p)].
                let mut g = 0.0;
                for i in 0..m {
                    g += t[i] * (x_new[i] - xp[i]) / sx;
                    bordered.rhs[i] = -bordered.r[i];
                }
                g += t[m] * (o_new - op) / so;
                bordered.rhs[m] = -g;
                let (big, perm, rhs) = (&bordered.big, &bordered.perm, &mut bordered.rhs);
                lu::solve_in_place(big, perm, rhs);
                for i in 0..m {
                    x_new[i] += rhs[i] * sx;
                }
                o_new += rhs[m] * so;
                if !o_new.is_finite() {
                    break;
                }
                if it + 1 == self.max_corrector && o_new > 0.0 {
                    // The last update gets its check too.
                    if let Ok(Some(rel)) =
                        bordered.factor(&mut hb, &mut ws, &x_new, o_new, &t, sx, so, ext)
                    {
                        if rel <= self.tolerance {
                            converged = Some((it + 1, rel));
                        }
                    }
                }
            }
            let Some((iterations, rel)) = converged else {
                step *= 0.5;
                if step < self.min_step {
                    branch.stop = BranchStop::StepTooSmall { omega };
                    break;
                }
                continue;
            };
            // Tangent at the new point (bordered matrix factored there with the old t).
            let old_t_omega = t[m];
            self.tangent(&mut bordered, &mut t);
            let fold = old_t_omega * t[m] < 0.0;
            // dΩ/ds goes linearly from old to new tangent over the step h: zero at
            // s* = h tp/(tp - tn), where Ω = Ω_prev + s_Ω tp s*/2.
            let fold_omega = fold.then(|| {
                let h = ((0..m)
                    .map(|i| ((x_new[i] - x[i]) / sx).powi(2))
                    .sum::<f64>()
                    + ((o_new - omega) / so).powi(2))
                .sqrt();
                let s_star = h * old_t_omega / (old_t_omega - t[m]);
                omega + so * old_t_omega * s_star / 2.0
            });
            x.copy_from_slice(&x_new);
            omega = o_new;
            self.push_point(&mut branch, model, &hb, &x, omega, rel, fold)?;
            if let Some(last) = branch.points.last_mut() {
                last.fold_omega = fold_omega;
            }
            progress(((omega - from) / (to - from)).clamp(0.0, 1.0));
            if (omega - to) * direction >= 0.0 {
                branch.stop = BranchStop::Reached;
                break;
            }
            if iterations <= 2 {
                step = (step * 1.5).min(self.max_step);
            } else if iterations >= 5 {
                step *= 0.7;
            }
        }
        if branch.points.len() >= self.max_points {
            branch.stop = BranchStop::MaxPoints;
        }
        Ok(branch)
    }

    /// `t ← normalised solution of [[R_x s_x, R_Ω s_Ω], [t_oldᵀ]] t = (0, 1)` (factored).
    fn tangent(&self, b: &mut Bordered, t: &mut [f64]) {
        let m = b.layout.len();
        b.rhs.fill(0.0);
        b.rhs[m] = 1.0;
        lu::solve_in_place(&b.big, &b.perm, &mut b.rhs);
        let norm = b.rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
        for (ti, v) in t.iter_mut().zip(&b.rhs) {
            *ti = v / norm;
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn push_point(
        &self,
        branch: &mut Branch,
        model: &Model,
        hb: &HarmonicBalance,
        x: &[f64],
        omega: f64,
        residual: f64,
        fold: bool,
    ) -> Result<()> {
        let layout = hb.layout();
        let mut harmonics = vec![Complex64::default(); hb.len()];
        layout.unpack(x, &mut harmonics);
        let sol = crate::solution::Solution {
            basis: *hb.basis(),
            dofs: model.dof_names().to_vec(),
            harmonics,
            termination: crate::Termination::Converged,
            history: vec![residual],
            history_seconds: Vec::new(),
            stats: Default::default(),
            wall_time: Default::default(),
        };
        let floquet = match &self.stability {
            Some(options) => Some(options.compute(model, &sol)?),
            None => None,
        };
        let prev = branch.points.last().and_then(|p| p.floquet.clone());
        let prev_stable = prev.as_ref().map(|f| f.is_stable());
        let stable = floquet.as_ref().map(|f| f.is_stable());
        // The kind comes from the unstable side, where the critical multiplier is outside.
        let bifurcation = match (prev_stable, stable) {
            (Some(true), Some(false)) => floquet.as_ref().and_then(|f| f.critical()),
            (Some(false), Some(true)) => prev.as_ref().and_then(|f| f.critical()),
            _ => None,
        };
        let max_abs = (0..model.n_dofs()).map(|i| sol.max_abs(i)).collect();
        let truncation = sol.truncation_estimate();
        branch.points.push(BranchPoint {
            parameter: omega,
            omega,
            harmonics: sol.harmonics,
            max_abs,
            residual,
            truncation,
            floquet,
            fold,
            fold_omega: None,
            bifurcation,
        });
        Ok(())
    }
}

/// A warm-started sweep over any parameter: `build(p)` gives the model and basis at `p`; each
/// point starts Newton from the previous one. It stops with [`BranchStop::NotConverged`] where
/// Newton fails (it does not follow folds). Stability as in [`Continuation`].
pub fn parameter_sweep(
    values: &[f64],
    mut build: impl FnMut(f64) -> Result<(Model, HarmonicBasis)>,
    stability: Option<FloquetOptions>,
    mut progress: impl FnMut(f64),
) -> Result<Branch> {
    let mut branch: Option<Branch> = None;
    let mut previous: Option<Vec<Complex64>> = None;
    let cont = Continuation {
        stability,
        ..Continuation::default()
    };
    for (i, &p) in values.iter().enumerate() {
        let (model, basis) = match build(p) {
            Ok(v) => v,
            Err(e) => match branch.as_mut() {
                // Keep the points so far.
                Some(b) => {
                    b.stop = BranchStop::InvalidParameter {
                        parameter: p,
                        reason: e.to_string(),
                    };
                    break;
                }
                None => return Err(e),
            },
        };
        let hb = HarmonicBalance::new(&model, basis)?;
        crate::solve::check_dense_for_continuation(&hb)?;
        let mut ws = hb.workspace();
        let newton = Newton::new().with_tolerance(cont.tolerance)?;
        let sol = match &previous {
            Some(q) if q.len() == hb.len() => newton.solve_from(&hb, q, &mut ws)?,
            _ => newton.solve(&hb, &mut ws)?,
        };
        let b = branch.get_or_insert_with(|| Branch {
            dofs: model.dof_names().to_vec(),
            harmonics: basis.harmonics(),
            points: Vec::new(),
            stop: BranchStop::Reached,
        });
        if !sol.is_converged() {
            b.stop = if i == 0 {
                BranchStop::StartFailed {
                    reason: sol.termination.to_string(),
                }
            } else {
                BranchStop::NotConverged { parameter: p }
            };
            break;
        }
        let mut x = vec![0.0; hb.layout().len()];
        hb.layout().pack(sol.harmonics(), &mut x);
        cont.push_point(b, &model, &hb, &x, basis.omega(), sol.residual(), false)?;
        if let Some(last) = b.points.last_mut() {
            last.parameter = p;
        }
        previous = Some(sol.harmonics().to_vec());
        progress((i + 1) as f64 / values.len() as f64);
    }
    branch.ok_or_else(|| Error::invalid("parameter sweep", "values", 0.0, "at least one value"))
}
