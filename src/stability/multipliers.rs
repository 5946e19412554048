//! The result of a Floquet analysis: the multipliers, how they sit relative to the unit
//! circle, and the reduced basis they were computed on.

use num_complex::Complex64;

use super::Orbit;
use nalgebra::DMatrix;

/// A multiplier counts as outside the unit circle once its modulus exceeds `1 + margin`.
pub const STABILITY_MARGIN: f64 = 1e-6;

/// How a multiplier sits relative to the unit circle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bifurcation {
    /// Real multiplier near +1.
    Fold,
    /// Real multiplier near −1.
    PeriodDoubling,
    /// A real multiplier through +1 where the branch does not turn: a symmetry-breaking
    /// (pitchfork) or transcritical branch point, where another branch crosses. Set by the
    /// continuation, which sees the branch's geometry.
    BranchPoint,
    /// Complex pair on the unit circle.
    NeimarkSacker,
}

/// Floquet multipliers of a periodic solution.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Floquet {
    /// The multipliers that decide stability, largest modulus first (neutral ones excluded).
    pub multipliers: Vec<Complex64>,
    /// Multipliers that are exactly 1 by construction (two per rigid-body mode), left out.
    #[serde(default)]
    pub neutral: usize,
    /// `max_i |x₀,i - x₀*,i| / s_i`: how far the shooting moved the HB state at `t = 0` to reach
    /// the exact periodic orbit, relative to the state scales (`s_q` the largest `|q|`, `s_v`
    /// the same times the fastest frequency). An independent error estimate of the HB orbit.
    /// On a reduced basis ([`Floquet::reduction`]) measured from the HB state's projection
    /// onto the basis, so the part of the state the basis cannot hold does not count.
    #[serde(default)]
    pub orbit_correction: f64,
    /// `true` if Newton shooting converged; otherwise the multipliers are those along the
    /// orbit started from the HB state (still accurate to about the HB error).
    #[serde(default)]
    pub polished: bool,
    /// The state `(q, q̇)` at `t = 0` of the orbit the multipliers belong to (the exact
    /// periodic orbit when [`Floquet::polished`]).
    #[serde(default)]
    pub orbit_start: Vec<f64>,
    /// Integration steps over all periods integrated: accepted, rejected and event re-steps of
    /// the Runge–Kutta flow, or sub-steps and piece ends of the exponential flow.
    #[serde(default)]
    pub steps: usize,
    /// The reduced basis the multipliers were computed on, with its accuracy estimate; `None`
    /// for the dense monodromy matrix in the model's DOFs.
    #[serde(default)]
    pub reduction: Option<Reduction>,
    /// The orbit the multipliers belong to ([`FloquetOptions::orbit`](crate::stability::FloquetOptions::orbit); the exact orbit where
    /// the HB orbit's pieces do not apply or the stability decision is too close to call).
    #[serde(default)]
    pub orbit: Orbit,
    /// For the HB orbit's multipliers: their [distance](Floquet::distance) to the exact
    /// orbit's on the same coordinates (on a reduced basis, what the basis does to the exact
    /// orbit is in [`Reduction::estimate`]), the larger of the last two measurements of a sweep (at its first point, every
    /// [`ORBIT_CHECK_EVERY`]-th and where the multipliers have moved by 0.2 since the last;
    /// a single analysis measures its own); `None` for the exact orbit.
    #[serde(default)]
    pub orbit_difference: Option<f64>,
    /// How far the start of the orbit the multipliers belong to lies from the HB state at
    /// `t = 0`, in the HB orbit's dynamic terms ([`orbit_distance`](crate::stability::orbit_distance)); 0 for the HB orbit's own
    /// multipliers.
    #[serde(default)]
    pub orbit_distance: f64,
    /// `Some(d)` where the shooting found another periodic orbit than the HB solution's: `d`
    /// (more than [`OTHER_ORBIT_DISTANCE`](crate::stability::OTHER_ORBIT_DISTANCE), or four times the HB solution's truncation estimate where that is larger) away, also when started again from the HB state,
    /// and with multipliers of another kind than the HB orbit's own (a strongly unstable
    /// orbit single shooting cannot hold, whose neighbour it glided onto). The multipliers are
    /// then the HB orbit's own ([`Orbit::Harmonic`]): from the exponential flow's pieces where
    /// every law is piecewise affine along it, from the Runge–Kutta flow of the variational
    /// equation along the HB orbit otherwise.
    #[serde(default)]
    pub other_orbit: Option<f64>,
}

/// How often a sweep measures the HB orbit's multipliers against the exact orbit's
/// ([`Orbit::Harmonic`]): at its first analysis and then at every this-many-th.
pub const ORBIT_CHECK_EVERY: usize = 32;

impl Floquet {
    /// Largest modulus.
    pub fn max_abs(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |m| m.norm())
    }

    /// How far the leading multipliers of `self` lie from those of `other`: the largest
    /// distance of a multiplier of either (modulus at least half the largest of both, at
    /// most 8 of each) to the nearest of the other.
    pub fn distance(&self, other: &Floquet) -> f64 {
        distance(&self.multipliers, &other.multipliers)
    }

    /// The multipliers as `[re, im]` pairs, largest modulus first (their JSON form).
    pub fn pairs(&self) -> Vec<[f64; 2]> {
        self.multipliers.iter().map(|m| [m.re, m.im]).collect()
    }

    /// The multipliers' moduli `|μ|`, largest first.
    pub fn moduli(&self) -> Vec<f64> {
        self.multipliers.iter().map(|m| m.norm()).collect()
    }

    /// `true` if every multiplier lies inside the unit circle: `max |μ| <= 1 +`
    /// [`STABILITY_MARGIN`].
    pub fn is_stable(&self) -> bool {
        self.max_abs() <= 1.0 + STABILITY_MARGIN
    }

    /// Number of real multipliers greater than `1 +` [`STABILITY_MARGIN`] (a fold or branch
    /// point changes it by one); real as in [`Floquet::critical`].
    pub fn real_unstable(&self) -> usize {
        self.multipliers
            .iter()
            .filter(|m| is_real(m) && m.re > 1.0 + STABILITY_MARGIN)
            .count()
    }

    /// The kind of the critical multiplier (the one of largest modulus): a complex pair is a
    /// Neimark–Sacker point, also at a small argument (a pair at 1.054 ± 0.064i leaves the
    /// circle as a pair, not through +1); a real one (or a pair within 1e-6 of the real axis,
    /// rounding of a double root) is a fold by its argument within 0.1 rad of 0, a period
    /// doubling within 0.1 rad of π.
    pub fn critical(&self) -> Option<Bifurcation> {
        let m = *self.multipliers.first()?;
        let angle = m.arg().abs();
        let real = is_real(&m);
        Some(if real && angle < 0.1 {
            Bifurcation::Fold
        } else if real && angle > std::f64::consts::PI - 0.1 {
            Bifurcation::PeriodDoubling
        } else {
            Bifurcation::NeimarkSacker
        })
    }
}

/// A multiplier within 1e-6 of its modulus of the real axis (a double real root splits into
/// a pair that close by rounding).
fn is_real(m: &Complex64) -> bool {
    m.im.abs() <= 1e-6 * m.norm()
}

/// The reduced basis of a Floquet analysis and how far its multipliers can be trusted.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Reduction {
    /// Size of the basis, `r + a` (the monodromy matrix is twice that square).
    pub dofs: usize,
    /// r, undamped modes kept (every mode below the cut-off).
    pub modes: usize,
    /// a, attachment modes (static responses to unit forces on the element coordinates, less
    /// those already in the span).
    pub attachment: usize,
    /// The cut-off ω_c in rad/s.
    pub cutoff: f64,
    /// The accuracy estimate: the largest distance `min_j |μ_i - μ'_j|` of the leading
    /// multipliers `μ_i` (modulus at least half the largest, at most 8) to those `μ'_j` on the
    /// basis with twice the cut-off (more if that adds no mode). `Some(0)` when the basis
    /// spans the whole space (a similarity transform: only the integrator's error is left);
    /// `None` when not estimated ([`FloquetOptions::estimate`](crate::stability::FloquetOptions::estimate)). For the HB orbit's
    /// multipliers ([`Orbit::Harmonic`]) the distance to the exact orbit's on the wider
    /// basis: the orbit's error and the basis's together.
    #[serde(default)]
    pub estimate: Option<f64>,
    /// Size of the comparison basis of the estimate.
    #[serde(default)]
    pub comparison_dofs: Option<usize>,
    /// With [`FloquetMethod::Arnoldi`](crate::stability::FloquetMethod::Arnoldi): the Krylov vectors (monodromy actions) the leading
    /// multipliers took; `estimate` is then, relative to the largest modulus, the larger of
    /// the last change of the leading Ritz values (the Krylov part) and the integration part,
    /// `‖(Φ_{h/2} − Φ_h) y‖` for the leading Ritz vector `y` (the Runge–Kutta steps are
    /// refined until it is below 1e-6); the basis is the model's own DOFs (`dofs`), nothing
    /// cut.
    #[serde(default)]
    pub krylov: Option<usize>,
}

/// The larger of `max_i min_j |a_i - b_j|` over the leading `a_i` and the same over the
/// leading `b_j`, leading meaning a modulus at least half the largest of both sets (at most 8
/// from each): a multiplier that only one basis has counts with its distance to the other's
/// nearest.
pub(crate) fn distance(a: &[Complex64], b: &[Complex64]) -> f64 {
    let top = a
        .first()
        .map_or(0.0, |m| m.norm())
        .max(b.first().map_or(0.0, |m| m.norm()));
    let one_way = |a: &[Complex64], b: &[Complex64]| {
        a.iter()
            .take(8)
            .filter(|m| m.norm() >= 0.5 * top)
            .map(|m| b.iter().map(|o| (m - o).norm()).fold(m.norm(), f64::min))
            .fold(0.0, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}

/// Eigenvalues sorted by modulus, largest first.
pub(crate) fn eigenvalues(a: &DMatrix<f64>) -> Vec<Complex64> {
    let mut m: Vec<Complex64> = a.complex_eigenvalues().iter().copied().collect();
    m.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    m
}
