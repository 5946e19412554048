//! `stop_spring`: a piecewise-linear multi-stage spring with free play,
//! `f = s(u) + d u̇` (dual-mass-flywheel arc springs, clutch dampers).

use super::{ForceLaw, LinearPart};
use crate::error::{check_non_negative, Error, Result};

/// One stage of a [`StopSpring`]: stiffness `stiffness` from `|u| = from` on.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    /// Where the stage starts, `|u| >= from` (>= 0, m or rad).
    pub from: f64,
    /// Its stiffness (>= 0, N/m or N m/rad).
    pub stiffness: f64,
}

/// A multi-stage spring: continuous, piecewise linear, `s(0) = 0`, plus viscous damping:
///
/// `f = s(u) + d u̇`, `s(u) = Σ_i k_i (min(u, a_{i+1}) - a_i)⁺` for `u >= 0`,
///
/// with stages `(a_i, k_i)`, `a_0 < a_1 < ...` (`a_{n} = ∞`): stiffness `k_i` on
/// `[a_i, a_{i+1})`, free play (`f = 0`) on `[0, a_0)`. The negative side is
/// `s(u) = -s⁻(-u)` with its own stages (`from` given as positive magnitudes), by default the
/// same stages (an odd spring). The stiffnesses must not decrease from stage to stage (a
/// progressive spring: free play, then the first springs, then stiffer ones and the stop).
///
/// **Linear part.** `k0` is the mean of the first non-zero stage stiffness of both sides and
/// `d0 = d`, offset 0: the spring engaged, its free play ignored. The slope at `u = 0` (the
/// trait's default) would be 0 for a spring with free play, which leaves a free-free
/// drivetrain's clutch without any stiffness in `K0`.
///
/// ```
/// use hbal::force::{ForceLaw, Stage, StopSpring};
/// // 0.05 rad free play, 50 N m/rad to 0.3 rad, then 400 N m/rad.
/// let spring = StopSpring::new(vec![
///     Stage { from: 0.05, stiffness: 50.0 },
///     Stage { from: 0.3, stiffness: 400.0 },
/// ]);
/// assert_eq!(spring.force(0.0, 0.04, 0.0), 0.0);
/// assert!((spring.force(0.0, 0.4, 0.0) - (50.0 * 0.25 + 400.0 * 0.1)).abs() < 1e-12);
/// assert!((spring.force(0.0, -0.4, 0.0) + 52.5).abs() < 1e-12); // odd by default
/// assert_eq!(spring.kinks(), vec![-0.3, -0.05, 0.05, 0.3]);
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StopSpring {
    /// Stages for `u > 0`, by increasing `from`; at least one.
    pub stages: Vec<Stage>,
    /// Stages for `u < 0` (`from` as magnitudes); default: `stages` (odd spring).
    #[serde(default)]
    pub negative: Option<Vec<Stage>>,
    /// Viscous damping d (>= 0, N s/m or N m s/rad), acting everywhere; default 0.
    #[serde(default)]
    pub damping: f64,
}

/// `(s(x), s'(x))` of one side at `x >= 0`.
#[inline]
fn side(stages: &[Stage], x: f64) -> (f64, f64) {
    let (mut f, mut k) = (0.0, 0.0);
    for (i, s) in stages.iter().enumerate() {
        if x <= s.from {
            break;
        }
        let end = stages.get(i + 1).map_or(f64::INFINITY, |n| n.from);
        f += s.stiffness * (x.min(end) - s.from);
        k = s.stiffness;
    }
    (f, k)
}

impl StopSpring {
    /// An odd spring with `stages`, no damping.
    pub fn new(stages: Vec<Stage>) -> Self {
        Self {
            stages,
            negative: None,
            damping: 0.0,
        }
    }

    /// Sets the stages of the negative side.
    pub fn with_negative(mut self, stages: Vec<Stage>) -> Self {
        self.negative = Some(stages);
        self
    }

    /// Sets the viscous damping d.
    pub fn with_damping(mut self, d: f64) -> Self {
        self.damping = d;
        self
    }

    /// The stages of the negative side.
    fn negative_stages(&self) -> &[Stage] {
        self.negative.as_deref().unwrap_or(&self.stages)
    }

    /// `(s(u), s'(u))`.
    #[inline]
    fn spring(&self, u: f64) -> (f64, f64) {
        if u >= 0.0 {
            side(&self.stages, u)
        } else {
            let (f, k) = side(self.negative_stages(), -u);
            (-f, k)
        }
    }
}

fn validate_side(context: &str, field: &str, stages: &[Stage]) -> Result<()> {
    if stages.is_empty() {
        return Err(Error::invalid(
            context,
            field,
            0.0,
            "a non-empty list of stages `{ from, stiffness }` (number of stages)",
        ));
    }
    for (i, s) in stages.iter().enumerate() {
        check_non_negative(context, &format!("{field}[{i}].from"), s.from)?;
        check_non_negative(context, &format!("{field}[{i}].stiffness"), s.stiffness)?;
        if i > 0 {
            let before = stages[i - 1];
            if s.from <= before.from {
                return Err(Error::invalid(
                    context,
                    format!("{field}[{i}].from"),
                    s.from,
                    format!(
                        "> {field}[{}].from = {} (stages by increasing `from`)",
                        i - 1,
                        before.from
                    ),
                ));
            }
            if s.stiffness < before.stiffness {
                return Err(Error::invalid(
                    context,
                    format!("{field}[{i}].stiffness"),
                    s.stiffness,
                    format!(
                        ">= {field}[{}].stiffness = {} (a progressive spring: no stage softer than the one before)",
                        i - 1,
                        before.stiffness
                    ),
                ));
            }
        }
    }
    Ok(())
}

#[typetag::serde(name = "stop_spring")]
impl ForceLaw for StopSpring {
    #[inline]
    fn force(&self, _theta: f64, u: f64, du: f64) -> f64 {
        self.spring(u).0 + self.damping * du
    }
    fn force_batch(&self, _theta: &[f64], u: &[f64], du: &[f64], out: &mut [f64]) {
        for ((o, &x), &v) in out.iter_mut().zip(u).zip(du) {
            *o = self.spring(x).0 + self.damping * v;
        }
    }
    #[inline]
    fn derivatives(&self, _theta: f64, u: f64, _du: f64) -> (f64, f64) {
        (self.spring(u).1, self.damping)
    }
    fn linear_part(&self) -> LinearPart {
        let first = |stages: &[Stage]| {
            stages
                .iter()
                .map(|s| s.stiffness)
                .find(|&k| k > 0.0)
                .unwrap_or(0.0)
        };
        LinearPart {
            stiffness: 0.5 * (first(&self.stages) + first(self.negative_stages())),
            damping: self.damping,
            offset: 0.0,
        }
    }
    fn kinks(&self) -> Vec<f64> {
        let (pos, neg) = (&self.stages, self.negative_stages());
        let mut kinks: Vec<f64> = neg.iter().rev().map(|s| -s.from).collect();
        kinks.extend(pos.iter().map(|s| s.from));
        // Both first stages at 0: one kink at 0, none if they have one stiffness (smooth).
        if let (Some(p), Some(n)) = (pos.first(), neg.first()) {
            if p.from == 0.0 && n.from == 0.0 {
                kinks.retain(|&k| k != 0.0);
                if p.stiffness != n.stiffness {
                    kinks.insert(neg.len() - 1, 0.0);
                }
            }
        }
        kinks
    }
    fn validate(&self, context: &str) -> Result<()> {
        validate_side(context, "stages", &self.stages)?;
        if let Some(neg) = &self.negative {
            validate_side(context, "negative", neg)?;
        }
        check_non_negative(context, "damping", self.damping)
    }
}
