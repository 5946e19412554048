//! SVG line plots (plotters, SVG backend only).

use std::path::Path;

/// One curve.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points `(x, y)`.
    pub points: Vec<(f64, f64)>,
    /// Draw markers instead of a line.
    pub markers: bool,
    /// Draw the line dashed.
    pub dashed: bool,
    /// Palette index (default: the series' position).
    pub color: Option<usize>,
}

impl Series {
    /// A line.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
            markers: false,
            dashed: false,
            color: None,
        }
    }

    /// Markers only.
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            markers: true,
            ..Self::line(label, points)
        }
    }

    /// A dashed line.
    pub fn dashed(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            dashed: true,
            ..Self::line(label, points)
        }
    }

    /// Sets the palette index (an empty label keeps the series out of the legend).
    pub fn with_color(mut self, color: usize) -> Self {
        self.color = Some(color);
        self
    }
}

/// An axis: label and whether it is logarithmic.
#[derive(Debug, Clone)]
pub struct Axis {
    /// Label.
    pub label: String,
    /// Logarithmic scale (non-positive values are dropped).
    pub log: bool,
}

impl Axis {
    /// A linear axis.
    pub fn linear(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: false,
        }
    }

    /// A logarithmic axis.
    pub fn log(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: true,
        }
    }
}

const COLORS: [plotters::style::RGBColor; 6] = [
    plotters::style::RGBColor(0, 0, 0),
    plotters::style::RGBColor(214, 39, 40),
    plotters::style::RGBColor(31, 119, 180),
    plotters::style::RGBColor(44, 160, 44),
    plotters::style::RGBColor(148, 103, 189),
    plotters::style::RGBColor(255, 127, 14),
];

/// Writes an SVG with the given curves to `path`.
pub fn line_plot(
    path: &Path,
    title: &str,
    x: &Axis,
    y: &Axis,
    series: &[Series],
) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let keep = |a: &Axis, v: f64| v.is_finite() && (!a.log || v > 0.0);
    let pts: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|&(px, py)| keep(x, px) && keep(y, py))
                .collect()
        })
        .collect();
    let all = pts.iter().flatten();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(px, py) in all {
        x0 = x0.min(px);
        x1 = x1.max(px);
        y0 = y0.min(py);
        y1 = y1.max(py);
    }
    if x0 > x1 {
        return Err("nothing to plot".into());
    }
    let pad = |lo: f64, hi: f64, log: bool| {
        if log {
            (lo / 1.5, hi * 1.5)
        } else if hi > lo {
            let d = 0.05 * (hi - lo);
            (lo - d, hi + d)
        } else {
            (lo - 1.0, hi + 1.0)
        }
    };
    let (x0, x1) = pad(x0, x1, x.log);
    let (y0, mut y1) = pad(y0, y1, y.log);
    // Head room for the legend (upper right) so it does not cover the curves.
    let rows = series
        .iter()
        .filter(|s| !s.label.is_empty())
        .count()
        .min(12) as f64;
    if y.log {
        y1 *= 10f64.powf(0.12 * rows * (y1 / y0).log10().max(1.0) / 4.0);
    } else {
        y1 += 0.09 * rows * (y1 - y0);
    }
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            let fmt_x = |v: &f64| axis_tick_label(*v, x0, x1, x.log);
            let fmt_y = |v: &f64| axis_tick_label(*v, y0, y1, y.log);
            chart
                .configure_mesh()
                .x_desc(x.label.as_str())
                .y_desc(y.label.as_str())
                .x_label_formatter(&fmt_x)
                .y_label_formatter(&fmt_y)
                .draw()?;
            for (i, (s, p)) in series.iter().zip(&pts).enumerate() {
                let color = COLORS[s.color.unwrap_or(i) % COLORS.len()];
                let labelled = !s.label.is_empty();
                if s.markers {
                    let a =
                        chart.draw_series(p.iter().map(|&c| Circle::new(c, 4, color.filled())))?;
                    if labelled {
                        a.label(s.label.as_str())
                            .legend(move |(lx, ly)| Circle::new((lx + 10, ly), 4, color.filled()));
                    }
                } else if s.dashed {
                    let a = chart.draw_series(DashedLineSeries::new(
                        p.iter().copied(),
                        6,
                        4,
                        color.stroke_width(2),
                    ))?;
                    if labelled {
                        a.label(s.label.as_str()).legend(move |(lx, ly)| {
                            PathElement::new(vec![(lx, ly), (lx + 8, ly)], color.stroke_width(2))
                        });
                    }
                } else {
                    let a = chart
                        .draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))?;
                    if labelled {
                        a.label(s.label.as_str()).legend(move |(lx, ly)| {
                            PathElement::new(vec![(lx, ly), (lx + 20, ly)], color.stroke_width(2))
                        });
                    }
                }
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }};
    }
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80);
    match (x.log, y.log) {
        (false, false) => draw!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
        (false, true) => draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?),
        (true, false) => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?),
        (true, true) => {
            draw!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
        }
    }
    root.present()?;
    Ok(())
}

/// A tick label on an axis from `lo` to `hi`: rounding noise next to zero is `0`, and enough
/// digits that neighbouring ticks (about a tenth of the range apart) differ; scientific
/// notation outside `[1e-3, 1e4)`.
///
/// ```
/// use hbal::report::tick_label;
/// assert_eq!(tick_label(3e-18, -1.0, 1.0), "0");
/// assert_ne!(tick_label(2.1e-4, 2.0e-4, 2.5e-4), tick_label(2.2e-4, 2.0e-4, 2.5e-4));
/// assert_eq!(tick_label(1500.0, 800.0, 6000.0), "1500");
/// assert_eq!(tick_label(0.25, 0.0, 1.0), "0.25");
/// ```
pub fn tick_label(v: f64, lo: f64, hi: f64) -> String {
    let magnitude = lo.abs().max(hi.abs());
    let step = ((hi - lo).abs() / 10.0).max(f64::MIN_POSITIVE);
    if !v.is_finite() {
        return String::new();
    }
    if v.abs() <= 1e-9 * magnitude.max(step) {
        return "0".into();
    }
    // One digit more than the step needs (plotters puts ticks at 1, 2 or 5 times a decade).
    let trim = |s: &str| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if !(1e-3..1e4).contains(&magnitude) {
        let digits = 1 + (magnitude / step).log10().ceil().clamp(0.0, 6.0) as usize;
        let s = format!("{v:.digits$e}");
        match s.split_once('e') {
            Some((mantissa, exponent)) => format!("{}e{exponent}", trim(mantissa)),
            None => s,
        }
    } else {
        let decimals = 1 + (-step.log10()).ceil().clamp(0.0, 8.0) as usize;
        trim(&format!("{v:.decimals$}"))
    }
}

/// [`tick_label`], or on a logarithmic axis (ticks a decade or a factor apart) three
/// significant digits of the value itself.
fn axis_tick_label(v: f64, lo: f64, hi: f64, log: bool) -> String {
    if !log {
        return tick_label(v, lo, hi);
    }
    let magnitude = v.abs().max(f64::MIN_POSITIVE);
    tick_label(v, v - 0.001 * magnitude, v + 0.001 * magnitude)
}
