//! Reports: SVG plots and timing for tables.

mod branch;
mod plot;
mod timing;

pub use branch::{branch_csv, branch_plot, branches_plot};
pub use plot::{line_plot, Axis, Series};
pub use timing::median_time;
