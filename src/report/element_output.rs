//! What an engineer reads off an element: its coordinate `u(t) = w·q(t)` and force
//! `f(t) = f(θ, u, u̇)` over a period, their harmonics, extremes and peak-to-peak values, the
//! fraction of the period spent in each contact state, and for a gear stage the transmission
//! error in µm, the mesh force and the dynamic factor.
//!
//! The force is sampled on a fine grid (8 times the basis's N, at least 4096 samples per
//! period) from the synthesised `u`, `u̇`. Its extremes are those of the law's samples; its
//! harmonics those of the copy of the law the AFT balanced (a time-varying stiffness
//! band-limited to 2H orders, [`ForceLaw::band_limited`](crate::force::ForceLaw::band_limited)),
//! so that its mean is the force of the static balance (a force that jumps at a contact edge
//! converges like the sampling), plus, where the basis has the tail correction on and it
//! applies, the force the harmonics above H add through the stiffness jumps
//! ([`HarmonicBalance::tail_forces`](crate::HarmonicBalance::tail_forces); not in the
//! extremes, which it changes by about the solution's error). The extremes of `u` are refined
//! to the precision of its harmonics ([`Solution::extremes`]).

use super::ElementReport;
use crate::harmonic::AftPlan;
use crate::model::{Element, Model};
use crate::solution::Solution;
use crate::Result;
use num_complex::Complex64;

/// One time signal over a period: harmonics `0..=H` (`x(θ) = Re Σ X_k e^{ikθ}`) and extremes.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Signal {
    /// `X_0 ..= X_H`.
    #[serde(skip)]
    pub harmonics: Vec<Complex64>,
    /// Smallest value over the period.
    pub min: f64,
    /// Largest value over the period.
    pub max: f64,
}

impl Signal {
    /// `max - min`.
    pub fn peak_to_peak(&self) -> f64 {
        self.max - self.min
    }

    /// The mean `X_0`.
    pub fn mean(&self) -> f64 {
        self.harmonics.first().map_or(0.0, |x| x.re)
    }
}

/// A gear stage's mesh, in the units engineers quote.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MeshOutput {
    /// Unit of the transmission error: `µm` (base radii) or `µrad` (a torsional stage).
    pub te_unit: &'static str,
    /// Mean transmission error (static deflection plus backlash offset).
    pub te_mean: f64,
    /// Peak-to-peak dynamic transmission error.
    pub te_peak_to_peak: f64,
    /// Mean mesh force (N; N m with a ratio): the static load.
    pub force_mean: f64,
    /// Largest mesh force over the period.
    pub force_max: f64,
    /// Largest deviation from the mean, `max |f - f̄|`: the dynamic mesh force.
    pub dynamic_force: f64,
    /// Dynamic factor `K_v = max|f| / |f̄|` (1 for a steady load; 0 when unloaded).
    pub dynamic_factor: f64,
}

impl MeshOutput {
    /// From the mesh's coordinate (transmission error, m or rad) and force.
    fn new(te_unit: &'static str, coordinate: &Signal, force: &Signal) -> Self {
        let scale = 1e6;
        let mean = force.mean();
        MeshOutput {
            te_unit,
            te_mean: coordinate.mean() * scale,
            te_peak_to_peak: coordinate.peak_to_peak() * scale,
            force_mean: mean,
            force_max: force.max,
            dynamic_force: (force.max - mean).max(mean - force.min),
            // Loaded on either flank: the largest |f| over the mean |f̄|.
            dynamic_factor: if mean != 0.0 {
                force.max.abs().max(force.min.abs()) / mean.abs()
            } else {
                0.0
            },
        }
    }
}

/// The outputs of one element.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ElementOutput {
    /// The element's name.
    pub name: String,
    /// The law's scene-file type (`backlash`, `mesh_stiffness`, ...; `gear_stage`).
    pub kind: String,
    /// Its coordinate `u = w·q`.
    pub coordinate: Signal,
    /// Its force `f(θ, u, u̇)`.
    pub force: Signal,
    /// Fraction of the period in each state between the law's kinks, from the lowest `u` up
    /// (named by [`ForceLaw::state_names`](crate::force::ForceLaw::state_names), else
    /// `u < κ1`, `κ1 < u < κ2`, ...); empty for a smooth law.
    pub states: Vec<(String, f64)>,
    /// For a gear stage: transmission error and mesh force.
    pub mesh: Option<MeshOutput>,
}

impl ElementOutput {
    /// The same outputs with the extremes and mean force of the exact periodic solution
    /// ([`ExactSolution::extremes`](crate::solve::piecewise::ExactSolution::extremes)), which
    /// the harmonics `0..=H` only approximate; the mesh outputs follow.
    pub fn with_exact(mut self, exact: &crate::solve::piecewise::ElementExtremes) -> Self {
        (self.coordinate.min, self.coordinate.max) = exact.coordinate;
        (self.force.min, self.force.max) = exact.force;
        if let Some(mean) = self.force.harmonics.first_mut() {
            *mean = num_complex::Complex64::new(exact.force_mean, 0.0);
        }
        if let Some(mesh) = &self.mesh {
            self.mesh = Some(MeshOutput::new(mesh.te_unit, &self.coordinate, &self.force));
        }
        self
    }
}

/// The outputs of every element of `model` on the periodic solution `sol`.
///
/// ```
/// use hbal::force::{Backlash, MeshProfile};
/// use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};
/// let model = Model::builder(&["x"])
///     .mass_diagonal(&[1.0])
///     .damping(hbal::nalgebra::DMatrix::from_element(1, 1, 0.1))
///     .element("contact", &[("x", 1.0)], Backlash::new(1.0, MeshProfile::Constant { stiffness: 1.0 }))
///     .load("x", 0, 0.1, 0.0)
///     .load("x", 1, 0.05, 0.0)
///     .build()?;
/// let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.7, 32)?)?;
/// let sol = Newton::new().solve(&hb, &mut hb.workspace())?;
/// let out = &hbal::report::element_outputs(&model, &sol)?[0];
/// // Loaded on the drive flank all the time: f = u - 1 with mean 0.1.
/// assert_eq!(out.states[2].0, "drive");
/// assert!((out.states[2].1 - 1.0).abs() < 1e-12);
/// assert!((out.force.mean() - 0.1).abs() < 1e-9);
/// # Ok::<(), hbal::Error>(())
/// ```
pub fn element_outputs(model: &Model, sol: &Solution) -> Result<Vec<ElementOutput>> {
    ElementReport::new(model).outputs(sol)
}

/// [`element_outputs`] with the tail correction's forces `tail` (`(element, harmonics)`).
pub(super) fn outputs_with_tail(
    model: &Model,
    sol: &Solution,
    tail: Vec<(usize, Vec<Complex64>)>,
) -> Result<Vec<ElementOutput>> {
    let basis = sol.basis();
    let h = basis.harmonics();
    let samples = (8 * basis.samples()).clamp(4096, 1 << 16);
    let fine = basis.with_samples(samples)?;
    let plan = AftPlan::new(fine);
    let mut scratch = plan.make_scratch();
    let omega = basis.fundamental();
    let n = model.n_dofs();
    let theta: Vec<f64> = (0..samples).map(|j| fine.shaft_angle(j)).collect();
    let (mut u, mut du, mut f) = (vec![0.0; samples], vec![0.0; samples], vec![0.0; samples]);
    let mut out = Vec::with_capacity(model.elements().len());
    for (index, e) in model.elements().iter().enumerate() {
        let coordinate: Vec<Complex64> = (0..=h)
            .map(|k| e.gather(&sol.harmonics()[k * n..(k + 1) * n]))
            .collect();
        plan.synthesize_into(
            &coordinate,
            |_| Complex64::new(1.0, 0.0),
            &mut u,
            &mut scratch,
        );
        plan.synthesize_into(
            &coordinate,
            |k| Complex64::new(0.0, k as f64 * omega),
            &mut du,
            &mut scratch,
        );
        // Extremes from the law itself; harmonics from the copy the AFT balanced (a
        // time-varying stiffness band-limited to 2H orders), so that the mean force is the
        // one of the static balance.
        if let Some(memory) = e.law().memory() {
            // A law with memory: march the period until its hysteresis loop closes.
            let mut buffers = crate::harmonic::march::MarchBuffers::new(samples, 0);
            crate::harmonic::march::march(
                memory,
                &theta,
                &u,
                &du,
                &mut f,
                0,
                |_, _| (0.0, 0.0),
                &mut buffers,
            )
            .map_err(|_| crate::Error::Solver {
                reason: format!(
                    "element `{}`: its hysteresis loop does not close over the period",
                    e.name()
                ),
            })?;
        } else {
            e.law().force_batch(&theta, &u, &du, &mut f);
        }
        let (fmin, fmax) = min_max(&f);
        if let (None, Some(balanced)) = (e.law().memory(), e.law().band_limited(samples, 2 * h)) {
            balanced.force_batch(&theta, &u, &du, &mut f);
        }
        if let Some(j) = f.iter().position(|x| !x.is_finite()) {
            return Err(crate::Error::NonFinite {
                what: format!(
                    "force of element `{}` at sample {j} (u = {:e})",
                    e.name(),
                    u[j]
                ),
            });
        }
        let states = states(e, &u);
        let mut force = vec![Complex64::default(); h + 1];
        plan.analyze_into(&mut f, &mut force, &mut scratch);
        // The coupling through the harmonics above H, which the solve balanced as well.
        if let Some((_, extra)) = tail.iter().find(|(i, _)| *i == index) {
            for (f, x) in force.iter_mut().zip(extra) {
                *f += x;
            }
        }
        let single = Solution::from_harmonics(*basis, vec![e.name().to_string()], coordinate, 0.0)?;
        let (umin, umax) = single.extremes(0);
        let coordinate = Signal {
            harmonics: single.harmonics().to_vec(),
            min: umin,
            max: umax,
        };
        let force = Signal {
            harmonics: force,
            min: fmin,
            max: fmax,
        };
        let mesh = e.gear_stage().map(|stage| {
            let unit = if stage.base_radii.is_some() {
                "µm"
            } else {
                "µrad"
            };
            MeshOutput::new(unit, &coordinate, &force)
        });
        out.push(ElementOutput {
            name: e.name().to_string(),
            kind: if e.gear_stage().is_some() {
                "gear_stage".into()
            } else {
                law_type(e)
            },
            coordinate,
            force,
            states,
            mesh,
        });
    }
    Ok(out)
}

/// The law's scene-file name (typetag's tag), or `law`.
fn law_type(e: &Element) -> String {
    let mut v = serde_json::to_value(e.law()).unwrap_or_default();
    // An element `offset` wraps the law: name the law inside.
    while v.get("type").and_then(|t| t.as_str()) == Some("offset") {
        v = v.get("law").cloned().unwrap_or_default();
    }
    v.get("type")
        .and_then(|t| t.as_str())
        .map_or_else(|| "law".into(), str::to_string)
}

/// Fractions of the samples `u` in each interval between the law's kinks.
fn states(e: &Element, u: &[f64]) -> Vec<(String, f64)> {
    let mut kinks = e.law().kinks();
    kinks.retain(|k| k.is_finite());
    kinks.sort_by(f64::total_cmp);
    kinks.dedup();
    if kinks.is_empty() {
        return Vec::new();
    }
    let mut counts = vec![0usize; kinks.len() + 1];
    for &x in u {
        counts[kinks.partition_point(|&k| k < x)] += 1;
    }
    let names = e.law().state_names();
    let label = |i: usize| -> String {
        if names.len() == counts.len() {
            return names[i].to_string();
        }
        match i {
            0 => format!("u < {:e}", kinks[0]),
            i if i == kinks.len() => format!("u > {:e}", kinks[i - 1]),
            i => format!("{:e} < u < {:e}", kinks[i - 1], kinks[i]),
        }
    };
    counts
        .iter()
        .enumerate()
        .map(|(i, &c)| (label(i), c as f64 / u.len() as f64))
        .collect()
}

fn min_max(x: &[f64]) -> (f64, f64) {
    x.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        })
}
