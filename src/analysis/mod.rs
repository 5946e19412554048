//! Whole analyses of a scene, as the command line runs them, returning one typed result each:
//! the layer every front end (the CLI, the HTML report, a binding, a batch runner) calls
//! instead of arranging the library's pieces itself.
//!
//! - [`solve()`]: one periodic solution with the method's fallbacks, automatic harmonics or
//!   the exact piecewise method, the error estimate, Floquet stability where it is available,
//!   the extremes and the element outputs, and the notes a user should read
//!   ([`SolveAnalysis`]; its serde form is `hbal solve --json`).
//! - [`sweep()`]: a speed sweep through turning points, with stability, automatic harmonics
//!   along the branch, the branches leaving it, every point's element outputs and where
//!   contacts open ([`SweepAnalysis`]; its serde form is `hbal sweep --json`), progress to an
//!   [`Observer`], stopped by the settings' [`Cancel`](crate::continuation::Cancel) token.
//! - [`check_speed`]: the options every subcommand shares, checked before any work.
//!
//! ```
//! use hbal::analysis::{solve, SolveSettings};
//! use hbal::scene::Scene;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let scene = Scene::load(std::path::Path::new(concat!(
//!     env!("CARGO_MANIFEST_DIR"),
//!     "/examples/scenes/duffing.toml"
//! )))?;
//! let analysis = solve(&scene, &SolveSettings::default())?;
//! assert!(analysis.solution.is_converged());
//! assert_eq!(analysis.stable(), Some(true));
//! assert_eq!(analysis.exit_code(), 0);
//! // What `hbal solve --json` prints:
//! let json = serde_json::to_value(&analysis)?;
//! assert_eq!(json["converged"], true);
//! // What `hbal sweep --from 0.5 --to 2.6 --json` prints: through both folds of the
//! // hardening Duffing oscillator.
//! use hbal::analysis::{sweep, Silent, SweepSettings};
//! let settings = SweepSettings { from: Some(0.5), ..SweepSettings::to(2.6) };
//! let branch = sweep(&scene, &settings, &mut Silent)?;
//! assert_eq!(branch.branch.folds(), 2);
//! assert_eq!(branch.exit_code(), 0);
//! assert_eq!(serde_json::to_value(&branch)?["reached"], true);
//! # Ok(())
//! # }
//! ```

mod branch_outputs;
mod compare;
mod element_record;
mod modes;
mod observer;
mod options;
mod output_choice;
mod parameter_sweep;
mod solve;
mod solve_record;
mod start_record;
mod sweep;
mod sweep_outcome;
mod sweep_record;
mod sweep_settings;
mod torus_lines;
mod torus_solve;
mod torus_sweep;

pub use branch_outputs::{contact_loss, point_outputs, ContactLoss};
pub use compare::{compare, CompareAnalysis, CompareAuto, CompareSettings, MethodComparison};
pub use element_record::order_of;
pub use modes::{excitation_orders, modes, CriticalSpeed, ModesAnalysis, ModesSettings};
pub use observer::{Observer, Silent};
pub use options::{check, check_speed, check_sweep_start, linear_frequencies};
pub use output_choice::{reported_dofs, shown_output, Shown, ALL_DOFS_UP_TO};
pub use parameter_sweep::{
    check_parameter_sweep, parameter_sweep, ParameterAuto, ParameterSweepAnalysis,
    ParameterSweepSettings,
};
pub use solve::{solve, AutoRecord, SolveAnalysis, SolveNote, SolveSettings, StabilityOutcome};
pub use start_record::{start_from_record, StartRecord};
pub use sweep::{check_sweep, sweep, SweepAnalysis};
pub use sweep_outcome::SweepNote;
pub use sweep_record::SCHEMA_VERSION;
pub use sweep_settings::{SweepSettings, SweepStart};
pub use torus_lines::{line_label, LineRecord, Spectrum};
pub use torus_solve::{torus_solve, BaseRecord, TorusSolveAnalysis, TorusSolveSettings, TOP_LINES};
pub use torus_sweep::{
    check_torus_sweep, torus_sweep, OrderCut, TorusPointRecord, TorusSweepAnalysis,
    TorusSweepSettings, CUTS_PER_ELEMENT,
};
