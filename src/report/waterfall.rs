//! Waterfall plot of a run-up: one amplitude spectrum over the orders per speed, stacked at the
//! speed it was computed at. Each order is a stem rising from its slice's baseline; its height
//! is the amplitude in decibels of the largest amplitude of the whole plot,
//! `h = max(0, 1 + 20 lg(|X| / max|X|) / range_dB)` of the slice spacing times
//! [`SLICE_HEIGHT`], so that weak orders stay visible next to a resonance.

use std::path::Path;

/// One spectrum of the waterfall.
#[derive(Debug, Clone)]
pub struct Slice {
    /// The speed it belongs to (the baseline's height).
    pub speed: f64,
    /// `(order, amplitude)` pairs, amplitudes ≥ 0.
    pub amplitudes: Vec<(f64, f64)>,
}

/// The labels and scale of a waterfall plot.
#[derive(Debug, Clone)]
pub struct Waterfall<'a> {
    /// The plot title.
    pub title: &'a str,
    /// The speed axis label with its unit, e.g. `speed (rpm)`.
    pub speed_label: &'a str,
    /// The amplitude unit, e.g. `µm`.
    pub unit: &'a str,
    /// Decibels below the largest amplitude that still show (the stem's foot), e.g. 60.
    pub range_db: f64,
    /// Orders drawn in colour (the excitation orders); the others are grey.
    pub highlight: &'a [f64],
}

/// Most slices drawn: a longer sweep is thinned out evenly in speed.
pub const MAX_SLICES: usize = 40;

/// A stem of full height spans this many (mean) slice spacings.
pub const SLICE_HEIGHT: f64 = 0.9;

/// The stem height of amplitude `a` as a fraction of the full height (largest amplitude
/// `max`, `range_db` decibels shown).
///
/// ```
/// use hbal::report::stem_height;
/// assert_eq!(stem_height(1.0, 1.0, 60.0), 1.0);
/// assert!((stem_height(0.001, 1.0, 60.0) - 0.0).abs() < 1e-12); // -60 dB
/// assert!((stem_height(0.1, 1.0, 60.0) - 2.0 / 3.0).abs() < 1e-12); // -20 dB
/// assert_eq!(stem_height(0.0, 1.0, 60.0), 0.0);
/// ```
pub fn stem_height(a: f64, max: f64, range_db: f64) -> f64 {
    if !(a > 0.0 && max > 0.0 && range_db > 0.0) {
        return 0.0;
    }
    (1.0 + 20.0 * (a / max).log10() / range_db).clamp(0.0, 1.0)
}

/// At most `max` slices, evenly spread over the speed range (the nearest slice to each of
/// `max` equally spaced speeds), in their original order.
pub fn thin_slices(slices: &[Slice], max: usize) -> Vec<&Slice> {
    if slices.len() <= max || max < 2 {
        return slices.iter().collect();
    }
    let (lo, hi) = slices
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s.speed), hi.max(s.speed))
        });
    let mut keep: Vec<usize> = (0..max)
        .filter_map(|j| {
            let target = lo + (hi - lo) * j as f64 / (max - 1) as f64;
            (0..slices.len()).min_by(|&a, &b| {
                (slices[a].speed - target)
                    .abs()
                    .total_cmp(&(slices[b].speed - target).abs())
            })
        })
        .collect();
    keep.sort_unstable();
    keep.dedup();
    keep.into_iter().map(|i| &slices[i]).collect()
}

/// Writes the waterfall of `slices` to `path` as SVG.
pub fn waterfall_plot(
    path: &Path,
    plot: &Waterfall,
    slices: &[Slice],
) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    let shown = thin_slices(slices, MAX_SLICES);
    let finite = |v: f64| v.is_finite();
    let max = shown
        .iter()
        .flat_map(|s| s.amplitudes.iter().map(|p| p.1))
        .filter(|&a| finite(a))
        .fold(0.0f64, f64::max);
    let (s0, s1) = shown
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s.speed), hi.max(s.speed))
        });
    let o1 = shown
        .iter()
        .flat_map(|s| s.amplitudes.iter().map(|p| p.0))
        .filter(|&o| finite(o))
        .fold(0.0f64, f64::max);
    // The folds start at 0 and ±∞ and skip NaN: no NaN reaches these comparisons.
    if shown.is_empty() || max <= 0.0 || o1 <= 0.0 || s1 < s0 {
        return Err("nothing to plot".into());
    }
    let spacing = if shown.len() > 1 {
        (s1 - s0) / (shown.len() - 1) as f64
    } else {
        s0.abs().max(1.0) * 0.1
    };
    let full = SLICE_HEIGHT * spacing;
    let root = SVGBackend::new(path, (1120, 640)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(plot.title, ("sans-serif", 20))?;
    let (plot_area, legend_area) = root.split_horizontally(900);
    let mut chart = ChartBuilder::on(&plot_area)
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..o1 * 1.04, (s0 - 0.5 * spacing)..(s1 + full * 1.05))?;
    let fmt_x = |v: &f64| super::tick_label(*v, 0.0, o1);
    let fmt_y = |v: &f64| super::tick_label(*v, s0, s1);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("order of the reference speed")
        .y_desc(plot.speed_label)
        .x_label_formatter(&fmt_x)
        .y_label_formatter(&fmt_y)
        .draw()?;
    let grey = RGBColor(150, 150, 150);
    let colour = |o: f64| {
        plot.highlight
            .iter()
            .position(|&h| (h - o).abs() <= 1e-9 * h.abs().max(1.0))
            .map_or(grey, |i| super::plot::COLORS[i % super::plot::COLORS.len()])
    };
    for s in &shown {
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(0.0, s.speed), (o1 * 1.04, s.speed)],
            RGBColor(215, 215, 215).stroke_width(1),
        )))?;
        chart.draw_series(
            s.amplitudes
                .iter()
                .filter(|&&(o, a)| finite(o) && finite(a))
                .map(|&(o, a)| (o, stem_height(a, max, plot.range_db)))
                .filter(|&(_, h)| h > 0.0)
                .map(|(o, h)| {
                    PathElement::new(
                        vec![(o, s.speed), (o, s.speed + h * full)],
                        colour(o).stroke_width(3),
                    )
                }),
        )?;
    }
    // Legend: the excitation orders in their colours, the other harmonics, and the scale.
    let legend: Vec<super::Series> = plot
        .highlight
        .iter()
        .enumerate()
        .map(|(i, o)| {
            super::Series::line(format!("order {}", super::significant(*o, 6)), Vec::new())
                .with_color(i)
        })
        .collect();
    let labelled: Vec<(usize, &super::Series)> = legend.iter().enumerate().collect();
    super::plot::draw_legend(&legend_area, &legend, &labelled)?;
    let rows = legend.len().min(super::plot::LEGEND_ROWS) as i32;
    let font = ("sans-serif", 15).into_font();
    let y = 30 + 22 * rows;
    legend_area.draw(&PathElement::new(
        vec![(4, y), (36, y)],
        grey.stroke_width(3),
    ))?;
    legend_area.draw(&Text::new(
        "other orders",
        (44, y - 8),
        font.clone().color(&BLACK),
    ))?;
    for (j, line) in [
        "stem height: amplitude".to_string(),
        format!("from {} dB up to", -plot.range_db),
        format!("{} {}", super::plot::significant(max, 4), plot.unit),
    ]
    .into_iter()
    .enumerate()
    {
        legend_area.draw(&Text::new(
            line,
            (4, y + 30 + 20 * j as i32),
            font.clone().color(&BLACK),
        ))?;
    }
    root.present()?;
    Ok(())
}
