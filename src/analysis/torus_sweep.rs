//! A speed sweep of a scene on several base frequencies: every base keeps its order of the
//! speed ([`crate::torus::TorusSweep`], natural continuation), with each point's convergence
//! and truncation estimates and the order cuts of every element coordinate's strongest lines.

use super::torus_lines::line_label;
use super::torus_solve::{plan_of, BaseRecord};
use super::Observer;
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::torus::{
    NewtonKrylov, TorusBalance, TorusSolution, TorusStability, TorusSweep, Truncation,
};

/// Sweeps run again with raised automatic caps where a point's estimate is above the
/// tolerance.
const EXTRA_PASSES: usize = 3;

/// Order cuts kept per element coordinate.
pub const CUTS_PER_ELEMENT: usize = 8;

/// What a torus sweep is asked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorusSweepSettings {
    /// First speed (the scene's unit; default: the scene's).
    pub from: Option<f64>,
    /// Last speed.
    pub to: f64,
    /// Evenly spaced speeds, at least 2.
    pub points: usize,
}

/// One point of the sweep.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TorusPointRecord {
    /// The speed (the scene's unit).
    pub speed: f64,
    /// Whether it converged.
    pub converged: bool,
    /// Its relative residual.
    pub relative_residual: f64,
    /// Newton steps.
    pub iterations: usize,
    /// Each base's truncation estimate.
    pub estimates: Vec<Option<f64>>,
}

/// One line of one element coordinate over the sweep.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OrderCut {
    /// The element.
    pub element: String,
    /// The combination `k`.
    pub k: Vec<i32>,
    /// `k` in words.
    pub label: String,
    /// Its order of the speed.
    pub order: f64,
    /// Its amplitude at every point of `points`.
    pub amplitudes: Vec<f64>,
    /// The largest amplitude over the converged points and the speed of that point (NaN
    /// where none converged).
    pub peak: (f64, f64),
}

/// A torus sweep (its serde form is `hbal sweep --json` of such a scene).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TorusSweepAnalysis {
    /// `rpm`, `hz` or `rad_s`.
    pub speed_unit: String,
    /// Why the scene is on the torus.
    pub why: String,
    /// The bases (the estimate: the largest over the converged points).
    pub bases: Vec<BaseRecord>,
    /// Lines of the index set.
    pub lines: usize,
    /// The points in order.
    pub points: Vec<TorusPointRecord>,
    /// Speeds where no point could be set up, with the reason.
    pub skipped: Vec<(f64, String)>,
    /// The strongest lines of every element coordinate over speed.
    pub order_cuts: Vec<OrderCut>,
    /// The stability statement.
    pub stability: TorusStability,
    /// With automatic caps: why a point's estimate stays above the tolerance (`None`: every
    /// converged point is within it, or fixed caps).
    pub caps_stopped: Option<String>,
    /// Every point's solution (not in the JSON).
    #[serde(skip)]
    pub solutions: Vec<TorusSolution>,
}

impl TorusSweepAnalysis {
    /// Points that did not converge and skipped speeds.
    pub fn failures(&self) -> usize {
        self.points.iter().filter(|p| !p.converged).count() + self.skipped.len()
    }

    /// 0 if every point converged (and automatic caps reached their tolerance), else 1.
    pub fn exit_code(&self) -> u8 {
        u8::from(self.failures() > 0 || self.caps_stopped.is_some())
    }
}

/// Checks the options of a torus sweep of `scene` before any work: at least 2 points, `from`
/// (default the scene's speed) and `to` finite speeds > 0.
pub fn check_torus_sweep(scene: &Scene, settings: &TorusSweepSettings) -> Result<()> {
    let plan = plan_of(scene, "sweep")?;
    let from = settings.from.unwrap_or(plan.speed);
    if settings.points < 2 {
        return Err(Error::InvalidOptions {
            option: "--points".into(),
            reason: format!("a sweep needs at least 2 points, got {}", settings.points),
        });
    }
    for (option, v) in [("--from", from), ("--to", settings.to)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::InvalidOptions {
                option: option.into(),
                reason: format!("must be a finite speed > 0, got {v}"),
            });
        }
    }
    Ok(())
}

/// Sweeps a torus scene over evenly spaced speeds; progress to `observer`.
///
/// ```
/// use hbal::analysis::{torus_sweep, Silent, TorusSweepSettings};
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/two_stage_train_torus.toml");
/// let scene = hbal::scene::Scene::load(std::path::Path::new(path)).unwrap();
/// let settings = TorusSweepSettings { from: Some(2000.0), to: 2100.0, points: 3 };
/// let a = torus_sweep(&scene, &settings, &mut Silent).unwrap();
/// assert_eq!((a.points.len(), a.exit_code()), (3, 0));
/// assert_eq!(a.order_cuts[0].amplitudes.len(), 3);
/// ```
pub fn torus_sweep(
    scene: &Scene,
    settings: &TorusSweepSettings,
    observer: &mut dyn Observer,
) -> Result<TorusSweepAnalysis> {
    check_torus_sweep(scene, settings)?;
    let plan = plan_of(scene, "sweep")?;
    let from = settings.from.unwrap_or(plan.speed);
    let n = settings.points;
    let per = plan.rad_s_per_speed;
    let speeds: Vec<f64> = (0..n)
        .map(|i| per * (from + (settings.to - from) * i as f64 / (n - 1) as f64))
        .collect();
    let tm = plan.bind(&scene.model)?;
    let solver = NewtonKrylov {
        tolerance: plan.tolerance,
        ..NewtonKrylov::default()
    };
    // Automatic caps: the largest the ends of the range need, for the whole sweep; then, where
    // a point of that sweep still has an estimate above the tolerance, the caps that point
    // needs and the sweep once more.
    let mut grid = Grid {
        caps: plan.caps.clone(),
        samples: plan.samples.clone(),
        truncation: plan.truncation,
    };
    if let Some(auto) = &plan.auto {
        observer.stage("choosing the caps at both ends");
        for w in [speeds[0], speeds[n - 1]] {
            grid.raise(&auto.solve(&tm, &plan.caps, &plan.samples, plan.truncation, w, &solver)?);
        }
    }
    let sweep = TorusSweep {
        solver,
        ..Default::default()
    };
    let mut hb = TorusBalance::new(tm.clone(), grid.set(plan)?, &grid.samples, speeds[0])?;
    observer.stage("sweeping");
    let mut result = sweep.run(&mut hb, &speeds, |i, _| {
        observer.progress((i + 1) as f64 / n as f64)
    })?;
    let mut caps_stopped = None;
    if let Some(auto) = &plan.auto {
        for pass in 0..=EXTRA_PASSES {
            let worst = result
                .points
                .iter()
                .filter(|p| p.converged)
                .map(|p| {
                    (
                        p.truncation
                            .iter()
                            .flatten()
                            .fold(0.0, |a: f64, &e| a.max(e)),
                        p.omega,
                    )
                })
                .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
            if worst.0 <= auto.tolerance {
                break;
            }
            let before = grid.caps.clone();
            if pass < EXTRA_PASSES {
                observer.stage("raising the caps where the sweep needs more");
                let o = auto.solve(
                    &tm,
                    &grid.caps,
                    &grid.samples,
                    grid.truncation,
                    worst.1,
                    &solver,
                )?;
                grid.raise(&o);
            }
            if grid.caps == before {
                caps_stopped = Some(format!(
                    "a truncation estimate of {:.1e} at {} {} is above the tolerance {:.0e} with the caps {:?} (automatic caps: {})",
                    worst.0,
                    crate::report::significant(worst.1 / per, 6),
                    scene.speed_unit,
                    auto.tolerance,
                    grid.caps,
                    if pass < EXTRA_PASSES { "they stop there" } else { "passes used up" }
                ));
                break;
            }
            hb = TorusBalance::new(tm.clone(), grid.set(plan)?, &grid.samples, speeds[0])?;
            observer.stage("sweeping again");
            result = sweep.run(&mut hb, &speeds, |i, _| {
                observer.progress((i + 1) as f64 / n as f64)
            })?;
        }
    }
    let (caps, samples) = (grid.caps, grid.samples);
    let sol_points: Vec<TorusPointRecord> = result
        .points
        .iter()
        .map(|p| TorusPointRecord {
            speed: p.omega / per,
            converged: p.converged,
            relative_residual: p.relative_residual,
            iterations: p.iterations,
            estimates: p.truncation.clone(),
        })
        .collect();
    let bases = (0..plan.bases.len())
        .map(|b| {
            let worst = result
                .points
                .iter()
                .filter(|p| p.converged)
                .filter_map(|p| p.truncation[b])
                .fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e))));
            BaseRecord {
                name: plan.bases.names()[b].clone(),
                order: plan.bases.ratios()[b],
                hz: None,
                cap: caps[b],
                samples: samples[b],
                estimate: worst,
            }
        })
        .collect();
    Ok(TorusSweepAnalysis {
        speed_unit: scene.speed_unit.to_string(),
        why: plan.why.clone(),
        bases,
        lines: hb.set().len(),
        order_cuts: order_cuts(scene, &result.points, per),
        points: sol_points,
        skipped: result
            .skipped
            .iter()
            .map(|(w, m)| (w / per, m.clone()))
            .collect(),
        stability: result.stability,
        caps_stopped,
        solutions: result.points,
    })
}

/// The [`CUTS_PER_ELEMENT`] lines of each element coordinate with the largest peak over the
/// points.
fn order_cuts(scene: &Scene, points: &[TorusSolution], per: f64) -> Vec<OrderCut> {
    let Some(first) = points.first() else {
        return Vec::new();
    };
    let mut cuts = Vec::new();
    for e in scene.model.elements() {
        let lines: Vec<Vec<f64>> = points
            .iter()
            .map(|p| {
                p.coordinate_lines(e.weights())
                    .iter()
                    .map(|q| q.norm())
                    .collect()
            })
            .collect();
        // Peaks over the converged points only (an unconverged iterate's lines are marked in
        // the points, never reported as a peak).
        let peak = |j: usize| {
            (0..points.len())
                .filter(|&i| points[i].converged)
                .map(|i| (lines[i][j], points[i].omega / per))
                .fold((0.0, f64::NAN), |a, b| if b.0 > a.0 { b } else { a })
        };
        let mut order: Vec<usize> = (1..first.indices.len()).collect();
        order.sort_by(|&a, &b| peak(b).0.total_cmp(&peak(a).0));
        for &j in order.iter().take(CUTS_PER_ELEMENT) {
            let k = first.indices[j].clone();
            cuts.push(OrderCut {
                element: e.name().to_string(),
                label: line_label(&first.bases, &k),
                order: first.order(j),
                k,
                amplitudes: lines.iter().map(|l| l[j]).collect(),
                peak: peak(j),
            });
        }
    }
    cuts
}

/// The caps, grid and truncation a sweep runs on.
struct Grid {
    caps: Vec<usize>,
    samples: Vec<usize>,
    truncation: Truncation,
}

impl Grid {
    /// At least what the automatic caps `o` reached (a diamond's total too).
    fn raise(&mut self, o: &crate::torus::AutoCapsOutcome) {
        for b in 0..self.caps.len() {
            self.caps[b] = self.caps[b].max(o.caps[b]);
            self.samples[b] = self.samples[b].max(o.samples[b]);
        }
        if let (Truncation::Diamond { total: a }, Truncation::Diamond { total: b }) =
            (self.truncation, o.truncation)
        {
            self.truncation = Truncation::Diamond { total: a.max(b) };
        }
    }

    fn set(&self, plan: &crate::scene::TorusPlan) -> Result<crate::torus::IndexSet> {
        crate::torus::IndexSet::new(&plan.bases, &self.caps, self.truncation)
    }
}
