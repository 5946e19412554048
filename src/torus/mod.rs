//! Harmonic balance on several base frequencies (a torus): the steady state of a gear train
//! whose meshes and engine orders have frequencies that share no short common period.
//!
//! Each base turns at `ω_b = r_b Ω` (fixed ratios `r_b` of the speed Ω, [`Bases`]); the
//! response is a sum of lines at the combination frequencies `ν_k = k·ω`,
//!
//! `q(t) = Re Σ_{k ∈ K} Q_k e^{i k·θ}`, `θ_b = ω_b t`,
//!
//! over an index set `K ⊂ Z^d` ([`IndexSet`]). Every element's law sees the angle of its own
//! base ([`TorusModel`]); the balance is written on the torus `θ ∈ [0, 2π)^d`, where
//! `d/dt = Σ_b ω_b ∂/∂θ_b`, so the linear part is `Z(ν_k) Q_k` per line exactly as in the
//! one-frequency engine and the forces come from an AFT on a `N_1 × … × N_d` grid
//! ([`TorusFft`]). The balance is condensed onto the element coordinates
//! ([`TorusBalance`]) and solved by Newton–Krylov ([`NewtonKrylov`]).
//!
//! Where the bases are commensurate (a common period), the torus solution restricted to the
//! line `θ_b = ω_b t + φ_b` is the periodic solution for the phasing φ: one torus solve answers
//! every mesh phasing at once. d = 1 is the one-frequency basis of [`crate::HarmonicBasis`],
//! which the rest of hbal uses.
//!
//! Where a contact edge is crossed between grid points, the AFT corrects its trapezoid sums
//! along each grid line of the element's own base, as the one-frequency engine does on its
//! period ([`crate::harmonic::kinks`]): the line's coordinate is a trigonometric polynomial
//! of that base's angle, whose crossings of the edge are found by Newton and whose
//! Euler–Maclaurin error is subtracted, written back as band-limited samples.
//!
//! ```
//! use hbal::{force::CubicSpring, torus::*, Model};
//! // A Duffing oscillator forced at 1 and √2 rad/s.
//! let mut duffing = CubicSpring::new(1.0, 0.5);
//! duffing.d = 0.1;
//! let model = Model::builder(&["x"]).mass_diagonal(&[1.0])
//!     .element("cubic", &[("x", 1.0)], duffing)
//!     .load("x", 1, 0.1, 0.0).load("x", 1, 0.1, 0.0).build().unwrap();
//! let bases = Bases::new(&[("a", 1.0), ("b", 2f64.sqrt())]).unwrap();
//! let tm = TorusModel::new(&model, bases).bind_load(1, "b").unwrap();
//! let set = IndexSet::new(tm.bases(), &[5, 5], Truncation::Diamond { total: 5 }).unwrap();
//! let hb = TorusBalance::new(tm, set, &[16, 16], 1.0).unwrap();
//! let sol = NewtonKrylov::default().solve(&hb, None).unwrap();
//! assert!(sol.converged && sol.relative_residual < 1e-10);
//! // The strongest line is the resonant forcing at 1 rad/s, then the one at √2:
//! let lines = sol.lines(0);
//! assert_eq!((lines[0].0.as_slice(), lines[1].0.as_slice()), (&[1, 0][..], &[0, 1][..]));
//! ```

mod anderson;
mod arclength;
mod auto_caps;
mod balance;
mod bases;
mod broyden;
mod edges;
mod element_force;
mod elements;
mod estimate;
mod fixed_point;
mod gmres;
mod grid;
mod index_set;
mod law_samples;
mod linear;
mod model;
mod newton_krylov;
mod solution;
mod sweep;

pub use anderson::TorusAnderson;
pub use arclength::{TorusArclength, TorusBranch};
pub use auto_caps::{AutoCaps, AutoCapsOutcome, CapsLevel};
pub use balance::{TorusBalance, TorusWorkspace};
pub use bases::Bases;
pub use broyden::TorusBroyden;
pub use fixed_point::TorusFixedPoint;
pub use grid::{TorusFft, TorusScratch, MAX_GRID};
pub use index_set::{Index, IndexSet, Truncation};
pub use model::TorusModel;
pub use newton_krylov::NewtonKrylov;
pub use solution::TorusSolution;
pub use sweep::{TorusStability, TorusSweep, TorusSweepResult};
