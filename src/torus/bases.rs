//! The base frequencies of a quasi-periodic response: `ω_b = r_b Ω`, `b = 1..d`.

use crate::error::{in_magnitude_range, Error, Result};

/// Named base frequencies `ω_b = r_b Ω` as fixed ratios `r_b` of the speed Ω (rad/s of the
/// reference shaft): an engine's half order (`r = 0.5`), a mesh frequency (`r` = teeth times
/// the shaft's order). All proportional to speed, so a speed sweep keeps them in ratio.
///
/// ```
/// use hbal::torus::Bases;
/// let b = Bases::new(&[("engine", 0.5), ("mesh 2", 19.0 * 23.0 / 67.0)]).unwrap();
/// assert_eq!((b.len(), b.index("mesh 2")), (2, Some(1)));
/// assert!(Bases::new(&[("a", 1.0), ("b", -2.0)]).is_err()); // a ratio must be positive
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bases {
    names: Vec<String>,
    ratios: Vec<f64>,
}

impl Bases {
    /// Largest number of bases d.
    pub const MAX: usize = 4;

    /// Bases from `(name, ratio)` pairs; an error names a ratio that is not finite and
    /// positive, a repeated name, or more than [`Bases::MAX`] bases.
    pub fn new(bases: &[(&str, f64)]) -> Result<Self> {
        if bases.is_empty() || bases.len() > Self::MAX {
            return Err(Error::invalid(
                "torus bases",
                "number of bases",
                bases.len() as f64,
                format!("in 1..={}", Self::MAX),
            ));
        }
        for (i, (name, r)) in bases.iter().enumerate() {
            if !(r.is_finite() && *r > 0.0 && in_magnitude_range(*r)) {
                return Err(Error::invalid(
                    format!("torus base `{name}`"),
                    "ratio",
                    *r,
                    "finite and > 0 (its frequency over the speed)",
                ));
            }
            if bases[..i].iter().any(|(n, _)| n == name) {
                return Err(Error::InvalidElement {
                    context: format!("torus base `{name}`"),
                    reason: "the name is given twice".into(),
                });
            }
        }
        Ok(Self {
            names: bases.iter().map(|(n, _)| n.to_string()).collect(),
            ratios: bases.iter().map(|(_, r)| *r).collect(),
        })
    }

    /// Number of bases d.
    pub fn len(&self) -> usize {
        self.ratios.len()
    }

    /// `false`: a valid set has at least one base.
    pub fn is_empty(&self) -> bool {
        self.ratios.is_empty()
    }

    /// The ratios `r_b`.
    pub fn ratios(&self) -> &[f64] {
        &self.ratios
    }

    /// The names.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The index of the base called `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }
}
