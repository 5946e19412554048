//! The options of a speed sweep ([`SweepSettings`]) and the harmonics it may start from
//! ([`SweepStart`]), with their documented defaults.

use crate::continuation::Cancel;
use crate::stability::Orbit;
use crate::Formulation;
use num_complex::Complex64;

/// Harmonics to start a sweep from (a previous solve's), with where they were computed.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepStart {
    /// Harmonic-major `Q[k · n + i]` on the scene's H.
    pub harmonics: Vec<Complex64>,
    /// The fundamental (rad/s) they were computed at, if known: the default first speed.
    pub omega: Option<f64>,
    /// Where they came from (a file name), for the notes.
    pub label: String,
}

/// What to do besides the scene's own settings (defaults: [`SweepSettings::to`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSettings {
    /// The first speed (the scene's unit); default the start's speed, else the scene's.
    pub from: Option<f64>,
    /// The last speed (the scene's unit).
    pub to: f64,
    /// Harmonics to start from.
    pub start: Option<SweepStart>,
    /// Floquet stability of every point (default `true`).
    pub stability: bool,
    /// The orbit whose multipliers a point gets (default [`Orbit::Exact`]).
    pub orbit: Orbit,
    /// The point limit (default the continuation's, 2000).
    pub max_points: Option<usize>,
    /// The largest continuation step (scaled arclength; default 0.5).
    pub max_step: f64,
    /// Evenly spaced speeds of a sweep with the exact piecewise method (default 101).
    pub points: usize,
    /// Follow the branches leaving the main one at its branch points and period doublings
    /// (default `false`; needs the stability).
    pub all_branches: bool,
    /// The error estimate of every point against 2H (default `true`).
    pub error_estimate: bool,
    /// The formulation of the harmonic balance (default [`Formulation::Auto`]).
    pub formulation: Formulation,
    /// The corrector's relative residual tolerance (default the continuation's, 1e-10).
    pub tolerance: Option<f64>,
    /// The element or DOF the order-cut plot shows ([`shown_output`](super::shown_output)).
    pub output: Option<String>,
    /// The DOFs reported in full ([`reported_dofs`](super::reported_dofs)).
    pub dofs: Option<String>,
    /// Set from outside to stop after the current point (the points so far are kept).
    pub cancel: Cancel,
}

impl SweepSettings {
    /// The default settings of a sweep to `to` (the scene's unit).
    pub fn to(to: f64) -> Self {
        Self {
            from: None,
            to,
            start: None,
            stability: true,
            orbit: Orbit::Exact,
            max_points: None,
            max_step: 0.5,
            points: 101,
            all_branches: false,
            error_estimate: true,
            formulation: Formulation::Auto,
            tolerance: None,
            output: None,
            dofs: None,
            cancel: Cancel::default(),
        }
    }
}
