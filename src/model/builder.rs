//! Validating builder for [`Model`].

use super::{Element, GearStage, Load, Model, SparseMatrix, SpeedLaw};
use crate::error::{Error, Result};
use crate::force::ForceLaw;
use nalgebra::DMatrix;

/// An element as given: name, `(DOF name, weight)` pairs and law, or a gear stage.
#[derive(Debug)]
enum PendingElement {
    Law(String, Vec<(String, f64)>, Box<dyn ForceLaw>),
    Stage(String, GearStage),
    Planetary(String, super::PlanetarySet),
}

/// A matrix as given: dense, or assembled from triplets.
#[derive(Debug, Clone)]
enum Input {
    Dense(DMatrix<f64>),
    Sparse(SparseMatrix),
}

/// Collects a model's parts; [`ModelBuilder::build`] validates them all.
#[derive(Debug)]
pub struct ModelBuilder {
    dofs: Vec<String>,
    mass: Option<Input>,
    damping: Option<Input>,
    stiffness: Option<Input>,
    hysteretic: Option<Input>,
    loads: Vec<(String, usize, f64, f64, Option<SpeedLaw>)>,
    elements: Vec<PendingElement>,
    /// The first triplet outside the DOFs: matrix, row, column.
    bad_triplet: Option<(&'static str, usize, usize)>,
}

impl ModelBuilder {
    pub(super) fn new(dofs: &[&str]) -> Self {
        Self {
            dofs: dofs.iter().map(|s| s.to_string()).collect(),
            mass: None,
            damping: None,
            stiffness: None,
            hysteretic: None,
            loads: Vec::new(),
            elements: Vec::new(),
            bad_triplet: None,
        }
    }

    /// Mass matrix M (n × n, symmetric positive definite). Required.
    pub fn mass(mut self, m: DMatrix<f64>) -> Self {
        self.mass = Some(Input::Dense(m));
        self
    }

    /// Diagonal mass matrix.
    pub fn mass_diagonal(self, m: &[f64]) -> Self {
        let n = m.len();
        self.mass(DMatrix::from_diagonal(&nalgebra::DVector::from_row_slice(
            &m[..n],
        )))
    }

    /// Structural damping D (n × n), default zero.
    pub fn damping(mut self, d: DMatrix<f64>) -> Self {
        self.damping = Some(Input::Dense(d));
        self
    }

    /// Structural stiffness K (n × n), default zero.
    pub fn stiffness(mut self, k: DMatrix<f64>) -> Self {
        self.stiffness = Some(Input::Dense(k));
        self
    }

    /// Hysteretic (structural) damping `H` (n × n), default zero: the damping force of
    /// harmonic `k >= 1` is `i H Q_k`, the same at every frequency, i.e. a viscous damping
    /// `c(ω) = H / ω` (a loss factor η on a stiffness k gives `H = η k`). It has no static part
    /// and no time-domain form: the time integration and the Floquet analysis refuse it.
    ///
    /// ```
    /// use hbal::nalgebra::DMatrix;
    /// // x'' + x = cos(t/2) with H = 0.1: |X| = 1 / |1 - 1/4 + 0.1 i|.
    /// let model = hbal::Model::builder(&["x"])
    ///     .mass_diagonal(&[1.0])
    ///     .stiffness(DMatrix::from_element(1, 1, 1.0))
    ///     .hysteretic(DMatrix::from_element(1, 1, 0.1))
    ///     .load("x", 1, 1.0, 0.0)
    ///     .build()?;
    /// let hb = hbal::HarmonicBalance::new(&model, hbal::HarmonicBasis::new(0.5, 2)?)?;
    /// let sol = hbal::Newton::new().solve(&hb, &mut hb.workspace())?;
    /// let x = sol.harmonics()[1].norm();
    /// assert!((x - 1.0 / (0.75f64.powi(2) + 0.01).sqrt()).abs() < 1e-12);
    /// # Ok::<(), hbal::Error>(())
    /// ```
    pub fn hysteretic(mut self, h: DMatrix<f64>) -> Self {
        self.hysteretic = Some(Input::Dense(h));
        self
    }

    /// Hysteretic damping `H` from triplets (see [`ModelBuilder::hysteretic`],
    /// [`ModelBuilder::mass_triplets`]).
    pub fn hysteretic_triplets(mut self, triplets: &[(usize, usize, f64)]) -> Self {
        self.hysteretic = self.assemble(triplets, "hysteretic damping");
        self
    }

    /// Mass matrix M from `(row, column, value)` triplets (DOF indices from 0; repeated
    /// positions add up, as in FE assembly). For large sparse models.
    ///
    /// ```
    /// use hbal::Model;
    /// let m = Model::builder(&["a", "b"])
    ///     .mass_triplets(&[(0, 0, 1.0), (1, 1, 2.0)])
    ///     .stiffness_triplets(&[(0, 0, 1.0), (0, 0, 1.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 1.0)])
    ///     .build()?;
    /// assert_eq!(m.k0().get(0, 0), 2.0);
    /// let err = Model::builder(&["a"]).mass_triplets(&[(0, 3, 1.0)]).build().unwrap_err();
    /// assert!(err.to_string().contains("(0, 3)"));
    /// # Ok::<(), hbal::Error>(())
    /// ```
    pub fn mass_triplets(mut self, triplets: &[(usize, usize, f64)]) -> Self {
        self.mass = self.assemble(triplets, "mass");
        self
    }

    /// Structural damping D from triplets (see [`ModelBuilder::mass_triplets`]).
    pub fn damping_triplets(mut self, triplets: &[(usize, usize, f64)]) -> Self {
        self.damping = self.assemble(triplets, "damping");
        self
    }

    /// Structural stiffness K from triplets (see [`ModelBuilder::mass_triplets`]).
    pub fn stiffness_triplets(mut self, triplets: &[(usize, usize, f64)]) -> Self {
        self.stiffness = self.assemble(triplets, "stiffness");
        self
    }

    /// Assembles triplets; an index outside the DOFs is kept for `build` to report.
    fn assemble(&mut self, triplets: &[(usize, usize, f64)], what: &'static str) -> Option<Input> {
        let n = self.dofs.len();
        if let Some(&(i, j, _)) = triplets.iter().find(|(i, j, _)| *i >= n || *j >= n) {
            self.bad_triplet.get_or_insert((what, i, j));
        }
        let inside: Vec<_> = triplets
            .iter()
            .copied()
            .filter(|(i, j, _)| *i < n && *j < n)
            .collect();
        Some(Input::Sparse(SparseMatrix::from_triplets(n, &inside)))
    }

    /// Adds `cos · cos(k Ω t) + sin · sin(k Ω t)` to the load on `dof` (k = 0: static, with
    /// `sin = 0`).
    pub fn load(mut self, dof: &str, order: usize, cos: f64, sin: f64) -> Self {
        self.loads.push((dof.to_string(), order, cos, sin, None));
        self
    }

    /// Adds a load harmonic that follows the speed Ω: `(cos + i sin) · T(Ω)` with `T` the
    /// [`SpeedLaw`] (a power of the speed, or a table of amplitude and phase over speed, for
    /// which `(cos, sin) = (1, 0)` takes the table as it is).
    ///
    /// ```
    /// use hbal::model::SpeedLaw;
    /// let model = hbal::Model::builder(&["propeller"])
    ///     .mass_diagonal(&[2.0])
    ///     .stiffness(nalgebra::DMatrix::from_element(1, 1, 100.0))
    ///     .load_over_speed("propeller", 0, -50.0, 0.0, SpeedLaw::power(2.0, 1000.0))
    ///     .build()
    ///     .unwrap();
    /// let at_2000_rpm = 2000.0 * std::f64::consts::TAU / 60.0;
    /// assert!((model.loads()[0].at(at_2000_rpm).0 + 200.0).abs() < 1e-9);
    /// ```
    pub fn load_over_speed(
        mut self,
        dof: &str,
        order: usize,
        cos: f64,
        sin: f64,
        law: SpeedLaw,
    ) -> Self {
        self.loads
            .push((dof.to_string(), order, cos, sin, Some(law)));
        self
    }

    /// Adds a force element `law` on `u = Σ w_i q_i` over the named DOFs.
    pub fn element(
        self,
        name: &str,
        weights: &[(&str, f64)],
        law: impl ForceLaw + 'static,
    ) -> Self {
        self.element_boxed(name, weights, Box::new(law))
    }

    /// Adds a boxed force element (e.g. deserialised from a scene file).
    pub fn element_boxed(
        mut self,
        name: &str,
        weights: &[(&str, f64)],
        law: Box<dyn ForceLaw>,
    ) -> Self {
        let w = weights.iter().map(|(d, w)| (d.to_string(), *w)).collect();
        self.elements
            .push(PendingElement::Law(name.to_string(), w, law));
        self
    }

    /// Adds a gear stage: the mesh on the transmission error `u = r_b1 θ1 - r_b2 θ2` of its
    /// driving and driven DOF ([`GearStage`] for the sign convention).
    pub fn gear_stage(mut self, name: &str, stage: GearStage) -> Self {
        self.elements
            .push(PendingElement::Stage(name.to_string(), stage));
        self
    }

    /// Adds a planetary set: its `2N` meshes as elements `name sun 1`, ..., `name ring N`
    /// ([`PlanetarySet`](super::PlanetarySet) for the coordinates and phasing).
    pub fn planetary(mut self, name: &str, set: super::PlanetarySet) -> Self {
        self.elements
            .push(PendingElement::Planetary(name.to_string(), set));
        self
    }

    /// Validates and builds the model.
    pub fn build(self) -> Result<Model> {
        let n = self.dofs.len();
        if n == 0 {
            return Err(Error::InvalidDofs {
                reason: "the model has no DOFs".into(),
            });
        }
        if n > Model::MAX_DOFS {
            return Err(Error::InvalidDofs {
                reason: format!("{n} DOFs, more than the limit of {}", Model::MAX_DOFS),
            });
        }
        let mut by_name = std::collections::HashMap::with_capacity(n);
        for (i, d) in self.dofs.iter().enumerate() {
            if d.trim().is_empty() {
                return Err(Error::InvalidDofs {
                    reason: format!("DOF {i} has an empty name"),
                });
            }
            if by_name.insert(d.as_str(), i).is_some() {
                return Err(Error::InvalidDofs {
                    reason: format!("DOF name `{d}` appears twice"),
                });
            }
        }
        if let Some((what, i, j)) = self.bad_triplet {
            return Err(Error::DimensionMismatch {
                context: format!("{what} matrix triplet ({i}, {j})"),
                expected: format!("row and column indices below {n}, the number of DOFs"),
                got: format!("({i}, {j})"),
            });
        }
        // The known names for an unknown-DOF message (the first 20 of a large model).
        let known = if n <= 20 {
            self.dofs.join(", ")
        } else {
            format!("{}, ... ({n} DOFs)", self.dofs[..20].join(", "))
        };
        let index = |context: &str, name: &str| -> Result<usize> {
            by_name.get(name).copied().ok_or_else(|| Error::UnknownDof {
                context: context.to_string(),
                name: name.to_string(),
                known: known.clone(),
            })
        };

        let mass = match self.mass.clone() {
            Some(m) => check_matrix("mass matrix", m, n)?,
            None => {
                return Err(Error::MassNotPositiveDefinite {
                    reason: "no mass matrix given".into(),
                })
            }
        };
        check_spd(&mass)?;
        let damping = match self.damping.clone() {
            Some(d) => check_matrix("damping matrix", d, n)?,
            None => SparseMatrix::zeros(n),
        };
        let stiffness = match self.stiffness.clone() {
            Some(k) => check_matrix("stiffness matrix", k, n)?,
            None => SparseMatrix::zeros(n),
        };
        let hysteretic = match self.hysteretic.clone() {
            Some(h) => check_matrix("hysteretic damping matrix", h, n)?,
            None => SparseMatrix::zeros(n),
        };

        let mut loads = Vec::with_capacity(self.loads.len());
        for (dof, order, c, s, law) in &self.loads {
            let ctx = format!("load on `{dof}` order {order}");
            let i = index(&ctx, dof)?;
            crate::error::check_finite(&ctx, "cos", *c)?;
            crate::error::check_finite(&ctx, "sin", *s)?;
            if *order == 0 && *s != 0.0 {
                return Err(Error::invalid(
                    &ctx,
                    "sin",
                    *s,
                    "0 on a static load (order 0, where sin(0 Ωt) = 0)",
                ));
            }
            if let Some(law) = law {
                law.validate(&ctx)?;
                if *order == 0 && law.phase.iter().any(|p| *p != 0.0) {
                    return Err(Error::InvalidElement {
                        context: ctx,
                        reason: "`phase` must be 0 on a static load (order 0): give the static load's sign in `amplitude`".into(),
                    });
                }
            }
            loads.push(Load {
                dof: i,
                order: *order,
                cos: *c,
                sin: *s,
                speed: law.clone().map(std::sync::Arc::new),
            });
        }

        let mut elements = Vec::with_capacity(self.elements.len());
        for pending in expand_planetaries(self.elements)? {
            let (name, weights, law, stage) = match pending {
                PendingElement::Law(name, weights, law) => (name, weights, law, None),
                PendingElement::Planetary(name, _) => {
                    return Err(Error::InvalidElement {
                        context: format!("planetary set `{name}`"),
                        reason: "not expanded into its meshes (an internal error)".into(),
                    })
                }
                PendingElement::Stage(name, stage) => {
                    stage.validate(&format!("gear stage `{name}`"))?;
                    let (weights, law) = stage.element();
                    let weights = weights.iter().map(|(d, w)| (d.to_string(), *w)).collect();
                    (name, weights, law, Some(stage))
                }
            };
            let ctx = format!("element `{name}`");
            if weights.is_empty() {
                return Err(Error::DimensionMismatch {
                    context: format!("{ctx} weights"),
                    expected: "at least one (DOF, weight) pair".into(),
                    got: "none".into(),
                });
            }
            let mut w = Vec::with_capacity(weights.len());
            for (dof, wi) in &weights {
                let i = index(&ctx, dof)?;
                crate::error::check_finite(&ctx, &format!("weights[{dof}]"), *wi)?;
                if w.iter().any(|(j, _)| *j == i) {
                    return Err(Error::InvalidDofs {
                        reason: format!("{ctx} names DOF `{dof}` twice"),
                    });
                }
                w.push((i, *wi));
            }
            if w.iter().all(|(_, wi)| *wi == 0.0) {
                return Err(Error::InvalidElement {
                    context: ctx,
                    reason: "every weight is 0: its coordinate u = Σ w q is always 0".into(),
                });
            }
            law.validate(&ctx)?;
            let linear = law.linear_part();
            crate::error::check_finite(&ctx, "linear part k0", linear.stiffness)?;
            crate::error::check_finite(&ctx, "linear part d0", linear.damping)?;
            crate::error::check_finite(&ctx, "linear part offset", linear.offset)?;
            elements.push(Element {
                name,
                weights: w,
                law,
                linear,
                stage,
            });
        }

        Ok(Model {
            dofs: self.dofs,
            mass,
            damping,
            stiffness,
            hysteretic,
            loads,
            elements,
        })
    }
}

/// Checks the size and the entries of a matrix and stores it sparse.
fn check_matrix(context: &str, m: Input, n: usize) -> Result<SparseMatrix> {
    let m = match m {
        Input::Dense(m) => {
            if m.nrows() != n || m.ncols() != n {
                return Err(Error::DimensionMismatch {
                    context: context.into(),
                    expected: format!("{n} x {n} (one row and column per DOF)"),
                    got: format!("{} x {}", m.nrows(), m.ncols()),
                });
            }
            if let Some(((i, j), v)) = m
                .iter()
                .enumerate()
                .map(|(idx, v)| ((idx % n, idx / n), v))
                .find(|(_, v)| !v.is_finite())
            {
                return Err(Error::invalid(context, format!("[{i}][{j}]"), *v, "finite"));
            }
            SparseMatrix::from_dense(&m)
        }
        Input::Sparse(m) => m,
    };
    if let Some((i, j, v)) = m.first_non_finite() {
        return Err(Error::invalid(context, format!("[{i}][{j}]"), v, "finite"));
    }
    Ok(m)
}

/// Symmetric (to 1e-12 of its largest entry) and positive definite (sparse Cholesky).
fn check_spd(m: &SparseMatrix) -> Result<()> {
    let scale = m.amax();
    let asym = m.asymmetry();
    if asym > 1e-12 * scale {
        return Err(Error::MassNotPositiveDefinite {
            reason: format!("not symmetric (largest |M - Mᵀ| entry {asym:.3e})"),
        });
    }
    if scale == 0.0 || !crate::linear::sparse_stiffness::is_positive_definite(m) {
        return Err(Error::MassNotPositiveDefinite {
            reason: "Cholesky factorisation failed (a zero or negative mass or inertia?)".into(),
        });
    }
    Ok(())
}

/// Every planetary set as its meshes (validated first).
fn expand_planetaries(pending: Vec<PendingElement>) -> Result<Vec<PendingElement>> {
    let mut out = Vec::with_capacity(pending.len());
    for p in pending {
        match p {
            PendingElement::Planetary(name, set) => {
                set.validate(&format!("planetary set `{name}`"))?;
                for (suffix, weights, law) in set.meshes() {
                    let weights = weights.iter().map(|(d, w)| (d.to_string(), *w)).collect();
                    out.push(PendingElement::Law(
                        format!("{name} {suffix}"),
                        weights,
                        law,
                    ));
                }
            }
            other => out.push(other),
        }
    }
    Ok(out)
}
