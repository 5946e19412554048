//! Reports: SVG plots and timing for tables.

mod plot;
mod timing;

pub use plot::{line_plot, Axis, Series};
pub use timing::median_time;
