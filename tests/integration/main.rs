//! The integration tests, one module per topic, in one test binary: one link instead of 42 files (a
//! fresh test build is about a minute shorter, and the binaries took 2 GB of disk). The
//! allocation count (`tests/no_allocation.rs`) keeps a binary of its own: it installs a global
//! allocator.
//!
//! One topic: `cargo test --test integration -- continuation::`; the heavy cases run in release
//! with `--ignored` (see `.ci/run`).

mod common;

mod accuracy_estimate;
mod aft;
mod analysis_compare;
mod analysis_modes;
mod analysis_solve;
mod analysis_sweep;
mod bad_input;
mod band_limited;
mod branch_switching;
mod car_drivetrain;
mod cli;
mod cli_auto_harmonics;
mod cli_branches;
mod cli_broken_scenes;
mod cli_dofs;
mod cli_start_files;
mod cli_sweep;
mod code_shape;
mod condensation;
mod condensation_branches;
mod contact_quadrature;
mod continuation;
mod damped_to_ground;
mod drivetrain;
mod element_output;
mod engine;
mod exit_codes;
mod floquet_references;
mod force_laws;
mod free_free;
mod free_free_time_domain;
mod gear_stage;
mod globalised_solve;
mod hard_cases;
mod hostile_input;
mod hostile_non_finite;
mod hostile_property;
mod hysteretic;
mod jacobian;
mod jenkins;
mod jenkins_cli;
mod kink_quadrature;
mod line_gears;
mod linear;
mod linear_sweep;
mod matrix_import;
mod matrix_import_bad_input;
mod modes;
mod new_laws;
mod nlvib_03;
mod no_operating_point;
mod options_contract;
mod order_cuts;
mod piecewise_exact;
mod piecewise_exact_cli;
mod planetary;
mod published_lines;
mod reference_solutions;
mod report;
mod s_curve;
mod scene_export;
mod shaft_line;
mod speed_loads;
mod stability_at_scale;
mod stability_exponential;
mod stability_harmonic_orbit;
mod stability_memory;
mod stability_rooms;
mod stability_time_domain;
mod stability_weak_ground;
mod stability_worker;
mod tail_correction;
mod threads;
mod torus;
mod torus_broyden;
mod torus_cli;
mod torus_scene;
mod two_level;
