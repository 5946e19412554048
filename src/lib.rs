//! # hbal: harmonic balance for powertrains
//!
//! hbal computes the periodic steady state of
//!
//! `M q̈ + D(t) q̇ + K(t) q + f_nl(t, q, q̇) = f(t)`
//!
//! (gear meshes with time-varying stiffness, backlash contacts, springs, user force laws)
//! directly in the frequency domain, following Bauer, Haslinger, Offner, Parikyan,
//! *Approaches for going beyond linear frequency domain powertrain simulation*
//! (RICAM report 2021-43). Stiffness and damping are split into a constant part and a
//! time-varying rest, `K(t) = K0 + K1(t)`, `D(t) = D0 + D1(t)`, and the iteration
//!
//! `(-(kΩ)² M + i kΩ D0 + K0) Q_k^{(n)} = F_k - [D1 q̇^{(n-1)} + K1 q^{(n-1)}]_k`
//!
//! alternates between per-harmonic linear solves and time-domain force evaluation (AFT).
//!
//! ## Data flow
//! [`Model`] (DOFs, `M`, `D`, `K`, loads, [`Element`]s with a [`force::ForceLaw`]) →
//! [`HarmonicBasis`] + [`HarmonicBalance`] (AFT plan, factored `Z_k`) → solver
//! ([`FixedPoint`]) → [`Solution`]. Beside it, [`timesim`] integrates the same model in time
//! as a reference.
//!
//! ```
//! use hbal::force::{MeshDamping, MeshProfile, MeshStiffness};
//! use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis, Model};
//! // The paper's two-shaft model at 6000 rpm, fundamental = mesh frequency (4 Ω).
//! let omega_mesh = 4.0 * 6000.0 * std::f64::consts::TAU / 60.0;
//! let model = Model::builder(&["gear"])
//!     .mass_diagonal(&[1e-3])
//!     .element("mesh", &[("gear", 1.0)], MeshStiffness::new(
//!         1,
//!         MeshProfile::Rectangular { one_tooth: 2.5e5, two_tooth: 5e5, contact_ratio: 1.5 },
//!         MeshDamping::Proportional(5.1639777949e-6),
//!     ))
//!     .load("gear", 0, 10.0, 0.0)
//!     .load("gear", 1, 1e-3 * 5e-4 * omega_mesh * omega_mesh, 0.0)
//!     .build()?;
//! let hb = HarmonicBalance::new(&model, HarmonicBasis::new(omega_mesh, 32)?)?;
//! // The paper's undamped iteration (γ = 0) diverges at this speed: mesh harmonics sit on the
//! // natural frequencies. That is a termination, not an error or a NaN:
//! let undamped = FixedPoint::new().solve(&hb, &mut hb.workspace())?;
//! assert_eq!(undamped.termination, hbal::Termination::Diverged);
//! // The paper's damping factor γ makes it converge:
//! let solution = FixedPoint::new()
//!     .with_gamma(0.5)?
//!     .with_max_iterations(1000)
//!     .solve(&hb, &mut hb.workspace())?;
//! assert!(solution.is_converged());
//! // Static part: L0 / K_mean = 10 / 3.75e5 (the mesh variation shifts it a little).
//! assert!((solution.cos_sin(0, 0).0 - 2.99e-5).abs() < 1e-7);
//! # Ok::<(), hbal::Error>(())
//! ```
#![warn(missing_docs)]

// `hbal::...` paths inside the crate too (the command line's modules are written with them).
extern crate self as hbal;

pub mod analysis;
pub mod catalog;
pub mod cli;
pub mod compare;
pub mod continuation;
pub mod error;
pub mod force;
pub mod harmonic;
pub mod jacobian;
pub mod linear;
pub mod model;
pub mod render;
pub mod report;
pub mod residual;
pub mod scene;
pub mod solution;
pub mod solve;
pub mod stability;
pub mod timesim;
pub mod torus;

pub use error::{Error, Result};
pub use harmonic::HarmonicBasis;
pub use linear::parallel::limit_threads_here;
pub use linear::Formulation;
pub use model::{Element, Model};
/// The linear-algebra crate of hbal's API (matrices of [`Model`]).
pub use nalgebra;
/// The complex numbers of hbal's harmonics.
pub use num_complex;
pub use residual::{AftBuffers, HarmonicBalance, Workspace};
pub use solution::{Solution, SolveStats, Termination};
pub use solve::{Anderson, Broyden, FixedPoint, Method, Newton};

/// The README's code blocks run as doctests, so the README stays true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// docs/library.md's code blocks run as doctests too.
#[doc = include_str!("../docs/library.md")]
#[cfg(doctest)]
pub struct LibraryDocDoctests;

/// docs/torus.md's code blocks run as doctests too.
#[doc = include_str!("../docs/torus.md")]
#[cfg(doctest)]
pub struct TorusDocDoctests;
