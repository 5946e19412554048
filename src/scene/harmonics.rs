//! The scene's `harmonics` table: H and N, or automatic harmonics with a tolerance and a cap.

use crate::solve::AutoHarmonics;
use crate::HarmonicBasis;
use serde::Deserialize;

/// `count` = H, `samples` = N, `auto`, `tolerance`, `max`, `control`, `tail_correction`
/// (docs/scenes.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Harmonics {
    count: Option<usize>,
    samples: Option<usize>,
    #[serde(default)]
    auto: bool,
    tolerance: Option<f64>,
    max: Option<usize>,
    /// What `auto` controls: `"solution"` (default), `"quantities"` or `"harmonics"`.
    control: Option<crate::solve::Control>,
    /// The tail correction of jumping coefficients (default: off at a fixed H, on with
    /// `auto`; see [`HarmonicBasis::with_tail_correction`]).
    tail_correction: Option<bool>,
}

/// A field path and a message.
fn fail(path: &str, message: String) -> (String, String) {
    (path.to_string(), message)
}

impl Harmonics {
    /// The harmonic basis at Ω = `omega` and, with `auto = true`, the automatic-harmonics
    /// settings; every error names its field.
    /// The stand-in of a scene without an operating point: `count` harmonics.
    pub(super) fn placeholder(count: usize) -> Self {
        Self {
            count: Some(count),
            samples: None,
            auto: false,
            tolerance: None,
            max: None,
            control: None,
            tail_correction: None,
        }
    }

    pub(super) fn basis(
        &self,
        omega: f64,
    ) -> Result<(HarmonicBasis, Option<AutoHarmonics>), (String, String)> {
        let hs = self;
        let auto = if hs.auto {
            let defaults = AutoHarmonics::default();
            let tolerance = hs.tolerance.unwrap_or(defaults.tolerance);
            if !(tolerance.is_finite() && (1e-14..1.0).contains(&tolerance)) {
                return Err(fail(
                    "harmonics.tolerance",
                    format!(
                        "must be in [1e-14, 1) (the estimate stops at rounding), got {tolerance}"
                    ),
                ));
            }
            let max_harmonics = hs.max.unwrap_or(defaults.max_harmonics);
            let limit = HarmonicBasis::MAX_HARMONICS / 2;
            if max_harmonics > limit {
                return Err(fail(
                    "harmonics.max",
                    format!(
                        "must be at most {limit} (its refinement doubles it), got {max_harmonics}"
                    ),
                ));
            }
            let first = hs.count.unwrap_or(8);
            if first == 0 {
                return Err(fail(
                    "harmonics.count",
                    "must be at least 1 with `auto = true` (H = 0 is a static analysis)"
                        .to_string(),
                ));
            }
            if max_harmonics < first.max(1) {
                return Err(fail(
                    "harmonics.max",
                    format!("must be at least the first H ({first}), got {max_harmonics}"),
                ));
            }
            Some(AutoHarmonics {
                tolerance,
                max_harmonics,
                control: hs.control.unwrap_or_default(),
                ..Default::default()
            })
        } else {
            for (field, given) in [
                ("tolerance", hs.tolerance.is_some()),
                ("max", hs.max.is_some()),
                ("control", hs.control.is_some()),
            ] {
                if given {
                    return Err(fail(
                        &format!("harmonics.{field}"),
                        "only applies with `auto = true`".to_string(),
                    ));
                }
            }
            None
        };
        let count = match (hs.count, hs.auto) {
            (Some(c), _) => c,
            (None, true) => 8,
            (None, false) => {
                return Err(fail(
                    "harmonics.count",
                    "is required (or `auto = true`)".to_string(),
                ))
            }
        };
        let mut basis =
            HarmonicBasis::new(omega, count).map_err(|e| fail("harmonics.count", e.to_string()))?;
        if let Some(on) = self.tail_correction {
            basis = basis.with_tail_correction(on);
        }
        if let Some(s) = self.samples {
            basis = basis
                .with_samples(s)
                .map_err(|e| fail("harmonics.samples", e.to_string()))?;
        }
        Ok((basis, auto))
    }
}
