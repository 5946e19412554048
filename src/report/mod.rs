//! Reports: element outputs, SVG plots, the HTML report and timing for tables.

mod branch;
mod csv_number;
mod element_output;
mod element_report;
mod html;
mod modes;
mod plot;
mod timing;
mod waterfall;

pub use branch::{branch_csv, branch_csv_of_dofs, branch_csv_orders, branch_plot, branches_plot};
pub use csv_number::csv_number;
pub use element_output::{element_outputs, ElementOutput, MeshOutput, Signal};
pub use element_report::ElementReport;
pub use html::{escape, HtmlReport};
pub use modes::{natural_frequencies, natural_frequencies_at, NaturalFrequencies};
pub use plot::{line_plot, significant, tick_label, Axis, Series};
pub use timing::median_time;
pub use waterfall::{
    stem_height, thin_slices, waterfall_plot, Slice, Waterfall, MAX_SLICES, SLICE_HEIGHT,
};
