//! The spectral lines of a torus solution in the engineer's terms: each line at the order
//! `k·r` of the speed, labelled by its combination of bases (`stage1 − 2 engine`), per DOF
//! and per element coordinate (a gear stage's transmission error).

use crate::torus::TorusSolution;
use num_complex::Complex64;

/// One spectral line.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LineRecord {
    /// The combination `k` (one integer per base).
    pub k: Vec<i32>,
    /// `k` in words: `stage1 + 2 engine`, `2 stage2 − stage1`.
    pub label: String,
    /// The order `k·r` of the speed (the reference shaft's).
    pub order: f64,
    /// Frequency, Hz.
    pub hz: f64,
    /// Amplitude `|Q_k|`.
    pub amplitude: f64,
    /// Phase of `Q_k` (rad): the line is `|Q_k| cos(k·θ + phase)`.
    pub phase: f64,
}

/// The lines of one DOF or element coordinate: mean, RMS of the alternating part (exact on
/// the torus: `√(Σ_{k≠0} |Q_k|² / 2)`) and the strongest lines.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Spectrum {
    /// The DOF's or element's name.
    pub name: String,
    /// The mean.
    pub mean: f64,
    /// RMS of the alternating part.
    pub rms: f64,
    /// The strongest lines, strongest first.
    pub lines: Vec<LineRecord>,
}

/// `k` in words over the base names: terms in base order, a coefficient 1 left out.
///
/// ```
/// let names = ["engine".to_string(), "stage1".to_string()];
/// assert_eq!(hbal::analysis::line_label(&names, &[-2, 1]), "stage1 − 2 engine");
/// assert_eq!(hbal::analysis::line_label(&names, &[4, 0]), "4 engine");
/// assert_eq!(hbal::analysis::line_label(&names, &[0, 0]), "mean");
/// ```
pub fn line_label(names: &[String], k: &[i32]) -> String {
    // Positive terms first, so that a line reads as a carrier with its sidebands.
    let mut terms: Vec<(i32, &str)> = k
        .iter()
        .zip(names)
        .filter(|(c, _)| **c != 0)
        .map(|(c, n)| (*c, n.as_str()))
        .collect();
    if terms.is_empty() {
        return "mean".into();
    }
    terms.sort_by_key(|t| t.0 < 0);
    let mut out = String::new();
    for (i, (c, n)) in terms.iter().enumerate() {
        let sign = match (i, *c < 0) {
            (0, true) => "−",
            (0, false) => "",
            (_, true) => " − ",
            (_, false) => " + ",
        };
        let a = c.unsigned_abs();
        if a == 1 {
            out.push_str(&format!("{sign}{n}"));
        } else {
            out.push_str(&format!("{sign}{a} {n}"));
        }
    }
    out
}

/// The spectrum called `name` of the lines `q` (line-major over the solution's index set),
/// keeping the `top` strongest; `speed_hz` is the speed Ω/2π.
pub(crate) fn spectrum(sol: &TorusSolution, name: &str, q: &[Complex64], top: usize) -> Spectrum {
    let hz = sol.omega / std::f64::consts::TAU;
    let mut lines: Vec<LineRecord> = (1..q.len())
        .map(|j| {
            let order = sol.order(j);
            LineRecord {
                k: sol.indices[j].clone(),
                label: line_label(&sol.bases, &sol.indices[j]),
                order,
                hz: order * hz,
                amplitude: q[j].norm(),
                phase: q[j].arg(),
            }
        })
        .collect();
    let rms = (lines.iter().map(|l| l.amplitude * l.amplitude).sum::<f64>() / 2.0).sqrt();
    lines.sort_by(|a, b| b.amplitude.total_cmp(&a.amplitude));
    lines.truncate(top);
    Spectrum {
        name: name.to_string(),
        mean: q.first().map_or(0.0, |m| m.re),
        rms,
        lines,
    }
}

/// The spectra of every DOF.
pub(crate) fn dof_spectra(sol: &TorusSolution, top: usize) -> Vec<Spectrum> {
    (0..sol.n_dofs())
        .map(|i| spectrum(sol, &sol.dofs[i], &sol.coordinate_lines(&[(i, 1.0)]), top))
        .collect()
}
