//! The mechanical model `M q̈ + D q̇ + K q + Σ_e w_e f_e(θ, w_e·q, w_e·q̇) = f(t)`.
//!
//! `M`, `D`, `K` are the constant structural matrices; every [`Element`] adds a force law `f_e`
//! acting on its local coordinate `u_e = w_e·q` and pushing back with `-w_e f_e`. The external
//! load `f(t)` is a sum of harmonics of the fundamental Ω ([`Load`]).
//!
//! Build one with [`Model::builder`]; `build()` validates everything and names the offending
//! item in its error.

mod builder;
mod element;
pub mod engine;
pub mod gear_stage;
mod load;
mod planetary;
pub mod rigid;
mod sparse;
pub mod speed_law;

pub use builder::ModelBuilder;
pub use element::Element;
pub use engine::{Cylinders, EngineExcitation, EngineOrder};
pub use gear_stage::GearStage;
pub use load::Load;
pub use planetary::PlanetarySet;
pub use rigid::RigidModes;
pub use sparse::SparseMatrix;
pub use speed_law::{SpeedLaw, Speeds};

use crate::error::{Error, Result};
use nalgebra::DMatrix;

/// The constant matrices as dense copies, for the parts of hbal that work densely (the full
/// formulation, the time integration, the monodromy matrix).
#[derive(Debug, Clone)]
pub struct DenseMatrices {
    /// M.
    pub mass: DMatrix<f64>,
    /// D (structural, without elements).
    pub damping: DMatrix<f64>,
    /// K (structural, without elements).
    pub stiffness: DMatrix<f64>,
    /// `D0 = D + Σ d0_e w_e w_eᵀ`.
    pub d0: DMatrix<f64>,
    /// `K0 = K + Σ k0_e w_e w_eᵀ`.
    pub k0: DMatrix<f64>,
    /// Hysteretic damping H (zero unless the model has it).
    pub hysteretic: DMatrix<f64>,
}

/// A validated model: DOF names, constant matrices (sparse), loads and force elements.
#[derive(Debug)]
pub struct Model {
    pub(crate) dofs: Vec<String>,
    pub(crate) mass: SparseMatrix,
    pub(crate) damping: SparseMatrix,
    pub(crate) stiffness: SparseMatrix,
    /// Hysteretic damping `H` ([`ModelBuilder::hysteretic`]).
    pub(crate) hysteretic: SparseMatrix,
    pub(crate) loads: Vec<Load>,
    pub(crate) elements: Vec<Element>,
}

impl Model {
    /// Starts a model with the given DOF names.
    ///
    /// ```
    /// use hbal::{force::LinearSpring, Model};
    /// let model = Model::builder(&["x"])
    ///     .mass_diagonal(&[2.0])
    ///     .element("spring", &[("x", 1.0)], LinearSpring::new(8.0, 0.1))
    ///     .load("x", 1, 1.0, 0.0)
    ///     .build()
    ///     .unwrap();
    /// assert_eq!(model.k0().get(0, 0), 8.0);
    /// // Bad input is an error that names the place:
    /// let err = Model::builder(&["x"]).mass_diagonal(&[1.0]).load("y", 1, 1.0, 0.0).build();
    /// assert!(err.unwrap_err().to_string().contains("unknown DOF `y`"));
    /// ```
    pub fn builder(dofs: &[&str]) -> ModelBuilder {
        ModelBuilder::new(dofs)
    }

    /// Number of degrees of freedom n.
    pub fn n_dofs(&self) -> usize {
        self.dofs.len()
    }

    /// DOF names in index order.
    pub fn dof_names(&self) -> &[String] {
        &self.dofs
    }

    /// Index of a DOF by name.
    pub fn dof_index(&self, name: &str) -> Option<usize> {
        self.dofs.iter().position(|d| d == name)
    }

    /// The DOFs that loads act on, ascending, each once.
    pub fn loaded_dofs(&self) -> Vec<usize> {
        let mut dofs: Vec<usize> = self.loads.iter().map(|l| l.dof).collect();
        dofs.sort_unstable();
        dofs.dedup();
        dofs
    }

    /// Mass matrix M.
    pub fn mass(&self) -> &SparseMatrix {
        &self.mass
    }

    /// Structural damping D (without elements).
    pub fn structural_damping(&self) -> &SparseMatrix {
        &self.damping
    }

    /// Structural stiffness K (without elements).
    pub fn structural_stiffness(&self) -> &SparseMatrix {
        &self.stiffness
    }

    /// Largest model (in DOFs) whose matrices are copied densely: `n²` entries each.
    pub const MAX_DENSE_DOFS: usize = 4096;

    /// Largest model in DOFs (a million; the harmonic-balance system of a large model is
    /// bounded further by [`MAX_SYSTEM_BYTES`](crate::residual::MAX_SYSTEM_BYTES)).
    pub const MAX_DOFS: usize = 1_000_000;

    /// Dense copies of M, D, K, D0, K0 for `context`, which works densely; an error for a
    /// model above [`Model::MAX_DENSE_DOFS`] DOFs.
    pub fn dense(&self, context: &str) -> Result<DenseMatrices> {
        let n = self.n_dofs();
        if n > Self::MAX_DENSE_DOFS {
            return Err(Error::invalid(
                context,
                "DOFs",
                n as f64,
                format!(
                    "<= {} for dense matrices ({:.1} GiB each here): use the condensed formulation (`--formulation condensed`)",
                    Self::MAX_DENSE_DOFS,
                    (n * n * 8) as f64 / (1u64 << 30) as f64
                ),
            ));
        }
        Ok(DenseMatrices {
            mass: self.mass.to_dense(),
            damping: self.damping.to_dense(),
            stiffness: self.stiffness.to_dense(),
            d0: self.d0().to_dense(),
            k0: self.k0().to_dense(),
            hysteretic: self.hysteretic.to_dense(),
        })
    }

    /// Loads.
    pub fn loads(&self) -> &[Load] {
        &self.loads
    }

    /// Force elements.
    pub fn elements(&self) -> &[Element] {
        &self.elements
    }

    /// The first element whose law has memory ([`ForceLaw::memory`](crate::force::ForceLaw::memory)),
    /// if any: the Floquet analysis is not available for such a model.
    pub fn memory_element(&self) -> Option<&Element> {
        self.elements.iter().find(|e| e.law().memory().is_some())
    }

    /// `true` if every element is linear and time-invariant
    /// ([`ForceLaw::is_linear_time_invariant`](crate::force::ForceLaw::is_linear_time_invariant)):
    /// the model is `M q̈ + D0 q̇ + K0 q = f(t)`, whose harmonics decouple (one solve per
    /// harmonic) and whose stability is that of its eigenvalues.
    pub fn is_linear_time_invariant(&self) -> bool {
        self.elements
            .iter()
            .all(|e| e.law().is_linear_time_invariant())
    }

    /// Hysteretic damping `H` (zero unless given, [`ModelBuilder::hysteretic`]).
    pub fn hysteretic(&self) -> &SparseMatrix {
        &self.hysteretic
    }

    /// `true` if the model has hysteretic damping: a frequency-domain law without a
    /// time-domain form.
    pub fn has_hysteretic_damping(&self) -> bool {
        self.hysteretic.nnz() > 0 && self.hysteretic.amax() > 0.0
    }

    /// An error for `analysis` (a time integration, a Floquet analysis) where the model has
    /// hysteretic damping, which has no time-domain form.
    pub fn refuse_hysteretic(&self, analysis: &str) -> Result<()> {
        if self.has_hysteretic_damping() {
            return Err(Error::InvalidElement {
                context: analysis.into(),
                reason: "the model has hysteretic damping (a loss factor: c = H/ω at each harmonic's frequency ω), which has no time-domain form; it exists in the frequency domain only".into(),
            });
        }
        Ok(())
    }

    /// `K0 = K + Σ_e k0_e w_e w_eᵀ`, the constant stiffness of the paper's split.
    pub fn k0(&self) -> SparseMatrix {
        self.stiffness.plus_outer(
            self.elements
                .iter()
                .map(|e| (e.linear.stiffness, e.weights.as_slice())),
        )
    }

    /// `D0 = D + Σ_e d0_e w_e w_eᵀ`, the constant damping of the paper's split.
    pub fn d0(&self) -> SparseMatrix {
        self.damping.plus_outer(
            self.elements
                .iter()
                .map(|e| (e.linear.damping, e.weights.as_slice())),
        )
    }

    /// Highest harmonic order of any load (0 for a static load only).
    pub fn max_load_order(&self) -> usize {
        self.loads.iter().map(|l| l.order).max().unwrap_or(0)
    }

    /// The highest order present: of any load, and of any element's time variation (a mesh
    /// order, [`ForceLaw::time_order`](crate::force::ForceLaw::time_order)). A basis needs at
    /// least this many harmonics.
    pub fn max_order(&self) -> usize {
        self.elements
            .iter()
            .filter_map(|e| e.law().time_order())
            .fold(self.max_load_order(), usize::max)
    }

    /// The load `f(θ)` at speed Ω from `(cos θ, sin θ)`, added into `out` (length n):
    /// `cos kθ`, `sin kθ` by the recurrence `e^{ikθ} = e^{iθ} e^{i(k-1)θ}` (no
    /// trigonometric call).
    pub fn load_into_phasor(&self, omega: f64, cos: f64, sin: f64, out: &mut [f64]) {
        for l in &self.loads {
            let (mut c, mut s) = (1.0, 0.0);
            for _ in 0..l.order {
                (c, s) = (c * cos - s * sin, s * cos + c * sin);
            }
            let (a, b) = l.at(omega);
            out[l.dof] += a * c + b * s;
        }
    }

    /// The load `f(θ)` at speed Ω and angle `θ = Ω t`, added into `out` (length n).
    pub fn load_into(&self, omega: f64, theta: f64, out: &mut [f64]) {
        for l in &self.loads {
            let k = l.order as f64;
            let (a, b) = l.at(omega);
            out[l.dof] += a * (k * theta).cos() + b * (k * theta).sin();
        }
    }

    /// `true` if some load follows the speed ([`Load::speed`]).
    pub fn has_speed_dependent_loads(&self) -> bool {
        self.loads.iter().any(|l| l.speed.is_some())
    }

    /// The fundamental's speeds Ω (rad/s) where every load's speed law is defined: `(0, ∞)`
    /// without tables over speed.
    pub fn load_speed_range(&self) -> (f64, f64) {
        self.loads
            .iter()
            .filter_map(|l| l.speed.as_deref())
            .map(|law| law.range())
            .fold((0.0, f64::INFINITY), |(a, b), (lo, hi)| {
                (a.max(lo), b.min(hi))
            })
    }

    /// An error naming the first load whose speed law is not defined over the speeds `lo`
    /// to `hi` (rad/s): a table over speed is never extrapolated.
    pub fn check_load_speeds(&self, lo: f64, hi: f64) -> Result<()> {
        let (lo, hi) = (lo.min(hi), lo.max(hi));
        for l in &self.loads {
            let Some(law) = &l.speed else { continue };
            if !law.covers(lo, hi) {
                let (a, b) = law.range_rpm();
                let rpm = 60.0 / std::f64::consts::TAU / law.fundamental_order;
                let needs = if lo == hi {
                    format!("{} rpm", short_rpm(lo * rpm))
                } else {
                    format!("{} to {} rpm", short_rpm(lo * rpm), short_rpm(hi * rpm))
                };
                return Err(Error::InvalidElement {
                    context: format!("load on `{}` order {}", self.dofs[l.dof], l.order),
                    reason: format!(
                        "its table over speed covers {} to {} rpm, and the analysis needs {needs}: extend the table (it is never extrapolated)",
                        short_rpm(a),
                        short_rpm(b),
                    ),
                });
            }
        }
        Ok(())
    }
}

/// A speed in rpm to 6 decimals, without trailing zeros.
fn short_rpm(x: f64) -> String {
    if x.is_finite() {
        format!("{}", (x * 1e6).round() / 1e6)
    } else {
        "∞".into()
    }
}
