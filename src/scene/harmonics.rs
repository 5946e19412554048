//! The scene's `harmonics` table: H and N, or automatic harmonics with a tolerance and a cap.

use crate::solve::AutoHarmonics;
use crate::HarmonicBasis;
use serde::Deserialize;

/// `count` = H, `samples` = N, `auto`, `tolerance`, `max`, `control`, `tail_correction`
/// (docs/scenes.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Harmonics {
    pub(super) count: Option<usize>,
    samples: Option<usize>,
    #[serde(default)]
    pub(super) auto: bool,
    tolerance: Option<f64>,
    pub(super) max: Option<usize>,
    /// What `auto` controls: `"solution"` (default), `"quantities"` or `"harmonics"`.
    control: Option<crate::solve::Control>,
    /// The tail correction of jumping coefficients (default: off at a fixed H, on with
    /// `auto`; see [`HarmonicBasis::with_tail_correction`]).
    tail_correction: Option<bool>,
    /// One fundamental or several base frequencies: `"auto"` (default), `"one"`, `"torus"`.
    #[serde(default)]
    pub(super) bases: super::torus_plan::BasesChoice,
    /// On the torus: the cap of each base, by name (`{ engine = 8, stage1 = 4 }`).
    #[serde(default)]
    pub(super) caps: std::collections::BTreeMap<String, usize>,
    /// On the torus: grid points per base, by name (default: a power of two >= 2 cap + 3).
    #[serde(default)]
    pub(super) grid: std::collections::BTreeMap<String, usize>,
    /// On the torus: a total-degree ("diamond") index set `Σ |k_b| <= total` inside the caps.
    pub(super) total: Option<usize>,
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
            bases: Default::default(),
            caps: Default::default(),
            grid: Default::default(),
            total: None,
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

    /// On the torus: the first base's one-frequency basis (a placeholder, H = its cap) after
    /// checking that no field of one fundamental is given.
    pub(super) fn torus_basis(
        &self,
        omega: f64,
        cap: usize,
    ) -> Result<(HarmonicBasis, Option<AutoHarmonics>), (String, String)> {
        for (field, given) in [
            ("samples", self.samples.is_some()),
            ("control", self.control.is_some()),
            ("tail_correction", self.tail_correction.is_some()),
        ] {
            if given {
                return Err(fail(
                    &format!("harmonics.{field}"),
                    "applies to one fundamental; on the torus give `caps` and `grid` per base"
                        .to_string(),
                ));
            }
        }
        let basis = HarmonicBasis::new(omega, cap.max(1))
            .map_err(|e| fail("harmonics.caps", e.to_string()))?;
        Ok((basis, None))
    }

    /// On the torus with `auto = true`: the tolerance of every base's truncation estimate and
    /// the largest cap (`max`, default 64).
    pub(super) fn torus_auto(&self) -> Result<Option<crate::torus::AutoCaps>, (String, String)> {
        if !self.auto {
            for (field, given) in [
                ("tolerance", self.tolerance.is_some()),
                ("max", self.max.is_some()),
            ] {
                if given {
                    return Err(fail(
                        &format!("harmonics.{field}"),
                        "only applies with `auto = true`".to_string(),
                    ));
                }
            }
            return Ok(None);
        }
        let defaults = crate::torus::AutoCaps::default();
        let tolerance = self.tolerance.unwrap_or(defaults.tolerance);
        if !(tolerance.is_finite() && (1e-12..1.0).contains(&tolerance)) {
            return Err(fail(
                "harmonics.tolerance",
                format!("must be in [1e-12, 1), got {tolerance}"),
            ));
        }
        let max_cap = self.max.unwrap_or(defaults.max_cap);
        if !(1..=crate::torus::IndexSet::MAX_CAP).contains(&max_cap) {
            return Err(fail(
                "harmonics.max",
                format!(
                    "must be in 1..={} on the torus (the largest cap of a base), got {max_cap}",
                    crate::torus::IndexSet::MAX_CAP
                ),
            ));
        }
        Ok(Some(crate::torus::AutoCaps {
            tolerance,
            max_cap,
            ..defaults
        }))
    }
}
