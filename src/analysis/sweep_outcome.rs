//! What a [`SweepAnalysis`] says beyond its points: its speeds in the scene's unit, the
//! failures that mark it (a stopped branch, a non-finite multiplier, a switched branch that
//! failed), where automatic harmonics fell short, its notes in words, and its exit code.

use super::sweep::SweepAnalysis;
use crate::continuation::{Branch, BranchStop};
use crate::solve::AutoHarmonics;

/// Something the user should read beside the branch.
#[derive(Debug, Clone, PartialEq)]
pub enum SweepNote {
    /// The start harmonics (their label) are not used: the exact method needs none.
    StartUnused(String),
    /// The harmonic orbit's stability is not used: the exact method's multipliers are exact.
    OrbitUnused,
    /// The start (its label) was computed at another speed than the first.
    StartSpeed {
        /// The start's label.
        label: String,
        /// Its speed (the scene's unit).
        computed_at: f64,
        /// The first speed.
        from: f64,
    },
    /// Automatic harmonics at the first speed.
    AutoHarmonics {
        /// The settings.
        settings: AutoHarmonics,
        /// The H chosen.
        harmonics: usize,
        /// Its error estimate in what the settings control.
        estimate: f64,
        /// Above the tolerance at the cap.
        capped: bool,
        /// The first speed (the scene's unit), where H was chosen.
        from: f64,
        /// Raised along the branch where a point exceeds the tolerance (else kept).
        raised: bool,
    },
    /// Where H changed along the branch: the first H, then `(Ω, H)` pairs.
    HarmonicsAlongBranch(usize, Vec<(f64, usize)>),
}

impl SweepAnalysis {
    /// The speed (the scene's unit) of the fundamental `omega` (rad/s).
    pub fn speed(&self, omega: f64) -> f64 {
        omega / self.omega_per_speed
    }

    /// The first point with a non-finite Floquet multiplier (its Ω): the library never gives
    /// one; should it, the sweep is marked failed rather than the value printed as `null`.
    pub fn non_finite_stability(&self) -> Option<f64> {
        let finite = |f: &crate::stability::Floquet| {
            f.multipliers
                .iter()
                .all(|m| m.re.is_finite() && m.im.is_finite())
        };
        let points = self.branch.points.iter();
        points
            .filter(|p| p.floquet.as_ref().is_some_and(|f| !finite(f)))
            .map(|p| p.omega)
            .next()
    }

    /// Where automatic harmonics chose H at the first speed and a point needs more: the
    /// largest estimate above the tolerance and its Ω.
    pub fn above_tolerance(&self) -> Option<(f64, f64)> {
        let auto = self.auto?;
        let estimates = self.branch.points.iter().filter_map(|p| {
            let e = auto
                .control
                .pick(p.error_estimate, p.error_estimate_harmonics);
            e.map(|e| (e, p.omega))
        });
        estimates
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .filter(|(e, _)| *e > auto.tolerance)
    }

    /// The switched branches that ended abnormally.
    pub fn failed_branches(&self) -> Vec<&Branch> {
        let all = self.secondary.iter();
        all.filter(|b| !b.stop.is_normal_end()).collect()
    }

    /// The exit code of the contract: 0 where the main branch reached the last speed, every
    /// switched branch ended normally and every multiplier is finite; 1 otherwise (the
    /// results are kept and marked).
    pub fn exit_code(&self) -> u8 {
        let reached = self.branch.stop == BranchStop::Reached;
        let clean = self.failed_branches().is_empty() && self.non_finite_stability().is_none();
        if reached && clean {
            0
        } else {
            1
        }
    }
}

impl SweepNote {
    /// The note in words, speeds in `unit`.
    pub fn describe(&self, unit: &str) -> String {
        match self {
            SweepNote::StartUnused(label) => format!(
                "--start {label} is not used: the exact piecewise solution needs no start"
            ),
            SweepNote::OrbitUnused => "--stability-orbit harmonic is not used: the exact piecewise solution's multipliers are its exact orbit's".into(),
            SweepNote::StartSpeed { label, computed_at, from } => format!(
                "--start {label} was computed at {computed_at} {unit}; the sweep starts at {from} {unit}"
            ),
            SweepNote::AutoHarmonics { settings, harmonics, estimate, capped, from, raised } => format!(
                "harmonics: auto, tolerance {:.0e}{}: H = {harmonics} (error estimate {estimate:.1e} at {from} {unit}{}), {}",
                settings.tolerance,
                settings.control.pick("", " on the harmonics 0..H"),
                if *capped { ", above the tolerance at the cap" } else { "" },
                if *raised { "raised along the branch where a point exceeds the tolerance" } else { "kept along the branch" }
            ),
            SweepNote::HarmonicsAlongBranch(first, changes) => {
                let mut steps = vec![format!("H = {first}")];
                steps.extend(changes.iter().map(|(w, h)| format!("H = {h} from {w:.6} rad/s")));
                format!("harmonics along the branch: {}", steps.join(", "))
            }
        }
    }
}
