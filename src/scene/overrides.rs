//! Solver settings given beside a scene (the command line's `--method`, `--harmonics`,
//! `--samples`, `--tolerance`, `--formulation`), applied to it in one place for every front
//! end ([`Overrides::apply`]).

use super::Scene;
use crate::solve::{AutoHarmonics, Control, Method};
use crate::{Error, Formulation, HarmonicBasis, Result};

/// The number of harmonics given beside a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HarmonicsOverride {
    /// Automatic harmonics, controlling what is named (else the scene's choice, by default
    /// the quantities).
    Auto(Option<Control>),
    /// A fixed H (automatic harmonics off).
    Count(usize),
}

impl std::str::FromStr for HarmonicsOverride {
    type Err = String;
    /// A count, `auto`, `auto:solution`, `auto:harmonics` or `auto:quantities`.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => return Ok(Self::Auto(None)),
            "auto:solution" => return Ok(Self::Auto(Some(Control::Solution))),
            "auto:harmonics" => return Ok(Self::Auto(Some(Control::Harmonics))),
            "auto:quantities" => return Ok(Self::Auto(Some(Control::Quantities))),
            _ => {}
        }
        s.parse::<usize>().map(Self::Count).map_err(|_| {
            format!(
                "expected a whole number of harmonics, `auto`, `auto:harmonics`, `auto:quantities` or `auto:solution`, got `{s}`"
            )
        })
    }
}

/// Solver settings that replace the scene's (`None`: the scene's own).
///
/// ```
/// use hbal::scene::{Overrides, Scene};
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/duffing.toml");
/// let mut scene = Scene::load(std::path::Path::new(path)).unwrap();
/// let overrides = Overrides { harmonics: Some("12".parse().unwrap()), ..Default::default() };
/// overrides.apply(&mut scene).unwrap();
/// assert_eq!(scene.basis.harmonics(), 12);
/// let bad = Overrides { tolerance: Some(2.0), ..Default::default() };
/// assert_eq!(bad.apply(&mut scene).unwrap_err().exit_code(), 2);
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Overrides {
    /// The solver by name (`fixed_point`, `newton`, `broyden`, `anderson`, `piecewise_exact`)
    /// with the scene's settings for it.
    pub method: Option<String>,
    /// H, or automatic harmonics.
    pub harmonics: Option<HarmonicsOverride>,
    /// Time samples N per period.
    pub samples: Option<usize>,
    /// The solver's relative residual tolerance.
    pub tolerance: Option<f64>,
    /// How the harmonic balance holds the unknowns (also of automatic harmonics).
    pub formulation: Formulation,
}

impl Overrides {
    /// On the torus only the tolerance applies (of Newton–Krylov's relative residual).
    fn apply_torus(&self, plan: &mut super::TorusPlan) -> Result<()> {
        let given = [
            ("--method", self.method.is_some()),
            ("--harmonics", self.harmonics.is_some()),
            ("--samples", self.samples.is_some()),
        ];
        if let Some((flag, _)) = given.iter().find(|g| g.1) {
            return Err(Error::InvalidOptions {
                option: flag.to_string(),
                reason: format!(
                    "applies to one fundamental; this scene is solved on several base frequencies ({}): give `harmonics.caps` (or `auto = true`) in the scene, or `harmonics.bases = \"one\"`",
                    plan.why
                ),
            });
        }
        if let Some(t) = self.tolerance {
            super::check_tolerance(t).map_err(|reason| Error::InvalidOptions {
                option: "--tolerance".into(),
                reason,
            })?;
            plan.tolerance = t;
        }
        Ok(())
    }

    /// Applies the overrides to `scene`.
    ///
    /// # Errors
    /// An unknown method, a tolerance out of range or with the exact method, an H or N the
    /// basis refuses ([`Error::InvalidOptions`] naming the option; bad input).
    pub fn apply(&self, scene: &mut Scene) -> Result<()> {
        if let Some(plan) = &mut scene.torus {
            return self.apply_torus(plan);
        }
        if let Some(name) = &self.method {
            scene.method = scene.method_named(name)?;
        }
        scene.method = self.with_tolerance(scene.method)?;
        scene.basis = self.basis(&scene.basis)?;
        self.apply_auto(&mut scene.auto);
        Ok(())
    }

    /// `method` with the tolerance override.
    ///
    /// # Errors
    /// A tolerance out of range, or one given to the exact method.
    pub fn with_tolerance(&self, method: Method) -> Result<Method> {
        let Some(t) = self.tolerance else {
            return Ok(method);
        };
        let bad = |reason: String| Error::InvalidOptions {
            option: "--tolerance".into(),
            reason,
        };
        super::check_tolerance(t).map_err(bad)?;
        let tolerance_error = |e: Error| bad(e.to_string());
        Ok(match method {
            Method::FixedPoint(o) => Method::FixedPoint(o.with_tolerance(t).map_err(tolerance_error)?),
            Method::Newton(o) => Method::Newton(o.with_tolerance(t).map_err(tolerance_error)?),
            Method::Broyden(o) => Method::Broyden(o.with_tolerance(t).map_err(tolerance_error)?),
            Method::Anderson(o) => Method::Anderson(o.with_tolerance(t).map_err(tolerance_error)?),
            // Exact: no residual tolerance to meet (a scene's `tolerance` is refused too).
            Method::PiecewiseExact(_) => return Err(bad(
                "does not apply to method piecewise_exact (its harmonics are exact to rounding): drop it".into(),
            )),
        })
    }

    /// `basis` with the harmonics count and samples overrides.
    pub fn basis(&self, basis: &HarmonicBasis) -> Result<HarmonicBasis> {
        let option = |option: &str| {
            let option = option.to_string();
            move |e: Error| Error::InvalidOptions {
                option: option.clone(),
                reason: format!("is refused: {e}"),
            }
        };
        let mut out = *basis;
        if let Some(HarmonicsOverride::Count(h)) = self.harmonics {
            let b = HarmonicBasis::new(basis.omega(), h)
                .map_err(option("--harmonics"))?
                .with_tail_correction_of(basis);
            // Keep the scene's N where it can still carry H harmonics.
            out = b.with_samples(basis.samples()).unwrap_or(b);
        }
        if let Some(n) = self.samples {
            out = out.with_samples(n).map_err(option("--samples"))?;
        }
        Ok(out)
    }

    /// The scene's automatic harmonics with the overrides: `auto[:control]` turns them on, a
    /// count off; the formulation is theirs too.
    pub fn apply_auto(&self, auto: &mut Option<AutoHarmonics>) {
        if let Some(a) = auto.as_mut() {
            a.formulation = self.formulation;
        }
        match self.harmonics {
            Some(HarmonicsOverride::Auto(control)) => {
                let a = auto.unwrap_or_default();
                *auto = Some(AutoHarmonics {
                    formulation: self.formulation,
                    control: control.unwrap_or(a.control),
                    ..a
                })
            }
            Some(HarmonicsOverride::Count(_)) => *auto = None,
            None => {}
        }
    }
}
