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

/// An axis: label and scale.
#[derive(Debug, Clone)]
pub struct Axis {
    /// Label, with the unit in parentheses.
    pub label: String,
    /// Logarithmic scale (non-positive values are dropped).
    pub log: bool,
    /// Choose the scale from the data: logarithmic where every value is positive and they span
    /// more than two decades, else linear (`log` is then ignored).
    pub auto: bool,
}

impl Axis {
    /// A linear axis.
    pub fn linear(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            log: false,
            auto: false,
        }
    }

    /// A logarithmic axis.
    pub fn log(label: impl Into<String>) -> Self {
        Self {
            log: true,
            ..Self::linear(label)
        }
    }

    /// An axis that is logarithmic where the values span more than two decades.
    pub fn auto(label: impl Into<String>) -> Self {
        Self {
            auto: true,
            ..Self::linear(label)
        }
    }

    /// Whether the axis is logarithmic for `values`.
    fn is_log(&self, values: impl Iterator<Item = f64>) -> bool {
        if !self.auto {
            return self.log;
        }
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for v in values.filter(|v| v.is_finite()) {
            if v <= 0.0 {
                return false;
            }
            lo = lo.min(v);
            hi = hi.max(v);
        }
        hi > 100.0 * lo
    }
}

/// The palette (black, then the "tab10" colours): series `i` is drawn in
/// `COLORS[i % COLORS.len()]`.
pub(super) const COLORS: [plotters::style::RGBColor; 10] = [
    plotters::style::RGBColor(0, 0, 0),
    plotters::style::RGBColor(214, 39, 40),
    plotters::style::RGBColor(31, 119, 180),
    plotters::style::RGBColor(44, 160, 44),
    plotters::style::RGBColor(148, 103, 189),
    plotters::style::RGBColor(255, 127, 14),
    plotters::style::RGBColor(140, 86, 75),
    plotters::style::RGBColor(227, 119, 194),
    plotters::style::RGBColor(188, 189, 34),
    plotters::style::RGBColor(23, 190, 207),
];

/// Most legend rows; further series are summed up in one line.
pub(super) const LEGEND_ROWS: usize = 24;

/// Writes an SVG with the given curves to `path`: the data fill the chart, the legend stands
/// to its right, outside the data.
pub fn line_plot(
    path: &Path,
    title: &str,
    x: &Axis,
    y: &Axis,
    series: &[Series],
) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let finite: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect();
    let x_log = x.is_log(finite.iter().map(|p| p.0));
    let y_log = y.is_log(finite.iter().map(|p| p.1));
    let keep = |log: bool, v: f64| v.is_finite() && (!log || v > 0.0);
    let pts: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .copied()
                .filter(|&(px, py)| keep(x_log, px) && keep(y_log, py))
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
    let (x0, x1) = pad(x0, x1, x_log);
    let (y0, y1) = pad(y0, y1, y_log);
    let labelled: Vec<(usize, &Series)> = series
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.label.is_empty())
        .collect();
    // The legend's width from its longest label (about 8 px per character at 15 px).
    let legend_width = labelled
        .iter()
        .take(LEGEND_ROWS)
        .map(|(_, s)| 50 + 8 * s.label.chars().count() as u32)
        .max()
        .map_or(0, |w| w.clamp(120, 320));
    let root = SVGBackend::new(path, (900 + legend_width, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let (plot_area, legend_area) = root.split_horizontally(900);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            let fmt_x = |v: &f64| axis_tick_label(*v, x0, x1, x_log);
            let fmt_y = |v: &f64| axis_tick_label(*v, y0, y1, y_log);
            chart
                .configure_mesh()
                .x_desc(x.label.as_str())
                .y_desc(y.label.as_str())
                .x_label_formatter(&fmt_x)
                .y_label_formatter(&fmt_y)
                .draw()?;
            for (i, (s, p)) in series.iter().zip(&pts).enumerate() {
                let color = COLORS[s.color.unwrap_or(i) % COLORS.len()];
                if s.markers {
                    chart.draw_series(p.iter().map(|&c| Circle::new(c, 3, color.filled())))?;
                } else if s.dashed {
                    chart.draw_series(DashedLineSeries::new(
                        p.iter().copied(),
                        6,
                        4,
                        color.stroke_width(2),
                    ))?;
                } else {
                    chart.draw_series(LineSeries::new(p.iter().copied(), color.stroke_width(2)))?;
                }
            }
        }};
    }
    let mut builder = ChartBuilder::on(&plot_area);
    builder
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80);
    match (x_log, y_log) {
        (false, false) => draw!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
        (false, true) => draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?),
        (true, false) => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?),
        (true, true) => {
            draw!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
        }
    }
    draw_legend(&legend_area, series, &labelled)?;
    root.present()?;
    Ok(())
}

/// The legend in its own area right of the chart: a sample of each labelled series (line,
/// dashes or marker in its colour) and its label, one row each.
pub(super) fn draw_legend<DB: plotters::prelude::DrawingBackend>(
    area: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    series: &[Series],
    labelled: &[(usize, &Series)],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    use plotters::prelude::*;
    let font = ("sans-serif", 15).into_font();
    let row = 22;
    for (r, &(i, s)) in labelled.iter().take(LEGEND_ROWS).enumerate() {
        let y = 30 + row * r as i32;
        let color = COLORS[series[i].color.unwrap_or(i) % COLORS.len()];
        if s.markers {
            area.draw(&Circle::new((20, y), 4, color.filled()))?;
        } else if s.dashed {
            for x in [4, 16, 28] {
                area.draw(&PathElement::new(
                    vec![(x, y), (x + 7, y)],
                    color.stroke_width(2),
                ))?;
            }
        } else {
            area.draw(&PathElement::new(
                vec![(4, y), (36, y)],
                color.stroke_width(2),
            ))?;
        }
        area.draw(&Text::new(
            s.label.clone(),
            (44, y - 8),
            font.clone().color(&BLACK),
        ))?;
    }
    if labelled.len() > LEGEND_ROWS {
        let y = 30 + row * LEGEND_ROWS as i32;
        area.draw(&Text::new(
            format!("… and {} more", labelled.len() - LEGEND_ROWS),
            (4, y - 8),
            font.color(&BLACK),
        ))?;
    }
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

/// `x` with `digits` significant digits, without trailing zeros; scientific notation outside
/// `[1e-3, 1e6)`.
///
/// ```
/// use hbal::report::significant;
/// assert_eq!(significant(19.4321, 4), "19.43");
/// assert_eq!(significant(2.5e-7, 4), "2.5e-7");
/// assert_eq!(significant(6000.0, 4), "6000");
/// ```
pub fn significant(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    let e = x.abs().log10().floor() as i32;
    if (-3..6).contains(&e) {
        let decimals = (digits as i32 - 1 - e).max(0) as usize;
        trim(format!("{x:.decimals$}"))
    } else {
        let s = format!("{x:.prec$e}", prec = digits.saturating_sub(1));
        match s.split_once('e') {
            Some((m, ex)) => format!("{}e{ex}", trim(m.to_string())),
            None => s,
        }
    }
}
