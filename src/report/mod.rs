//! Reports: element outputs, SVG plots and timing for tables.

mod branch;
mod element_output;
mod plot;
mod timing;

pub use branch::{branch_csv, branch_plot, branches_plot};
pub use element_output::{element_outputs, ElementOutput, MeshOutput, Signal};
pub use plot::{line_plot, Axis, Series};
pub use timing::median_time;
