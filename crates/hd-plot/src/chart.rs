//! The framed chart every panel is drawn in: axes, tick labels, grid, axis descriptions,
//! and the legend.

use plotters::chart::{ChartContext, SeriesLabelPosition};
use plotters::coord::Shift;
use plotters::coord::ranged1d::Ranged;
use plotters::prelude::*;

use crate::axis::{Axis, LABELS};
use crate::output::DrawError;
use crate::style;

/// A chart whose two axes are [`Axis`] values.
pub(crate) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<Axis, Axis>>;

/// What goes around the plotting area.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame<'a> {
    /// Panel caption above the plotting area, if any.
    pub caption: Option<&'a str>,
    /// x-axis description, with unit.
    pub x_label: &'a str,
    /// y-axis description, with unit.
    pub y_label: &'a str,
    /// Draw vertical grid lines.
    pub x_grid: bool,
}

impl<'a> Frame<'a> {
    /// A frame with axis descriptions, a full grid and no caption.
    pub(crate) fn new(x_label: &'a str, y_label: &'a str) -> Self {
        Frame { caption: None, x_label, y_label, x_grid: true }
    }

    /// The same frame with a panel caption.
    pub(crate) fn caption(self, caption: &'a str) -> Self {
        Frame { caption: Some(caption), ..self }
    }
}

/// Draw the figure title across the top of `root` and return the area below it.
pub(crate) fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, DrawError> {
    let below_margin = root.margin(10, 0, 0, 0);
    Ok(below_margin.titled(title, style::text(style::TITLE_PX))?)
}

/// Build a chart over `x` × `y` on `area` and draw its frame.
pub(crate) fn framed<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    frame: Frame<'_>,
    x: Axis,
    y: Axis,
) -> Result<Chart<'a, DB>, DrawError> {
    let mut builder = ChartBuilder::on(area);
    builder.margin(12).margin_right(28).x_label_area_size(60).y_label_area_size(100);
    if let Some(caption) = frame.caption {
        builder.caption(caption, style::text(style::CAPTION_PX));
    }
    let mut chart = builder.build_cartesian_2d(x, y)?;
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(LABELS)
        .y_labels(LABELS)
        .x_desc(frame.x_label)
        .y_desc(frame.y_label)
        .label_style(style::text(style::TICK_PX))
        .axis_desc_style(style::text(style::AXIS_LABEL_PX))
        .bold_line_style(BLACK.mix(0.15))
        .light_line_style(BLACK.mix(0.05));
    if !frame.x_grid {
        mesh.disable_x_mesh();
    }
    mesh.draw()?;
    Ok(chart)
}

/// Draw the legend of the labelled series in the corner of the plot that `points`
/// (the plotted data) leave emptiest.
pub(crate) fn legend<'a, 'p, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    points: impl IntoIterator<Item = &'p (f64, f64)>,
) -> Result<(), DrawError> {
    let corner = emptiest_corner(chart, points);
    chart
        .configure_series_labels()
        .position(corner)
        .margin(12)
        .label_font(style::text(style::LEGEND_PX))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .draw()?;
    Ok(())
}

/// The upper or lower, left or right corner with the fewest data points near it.
fn emptiest_corner<'p, DB: DrawingBackend>(
    chart: &Chart<'_, DB>,
    points: impl IntoIterator<Item = &'p (f64, f64)>,
) -> SeriesLabelPosition {
    let spec = chart.as_coord_spec();
    // Position as a fraction of the axis, 0 at the low end.
    let fraction = |axis: &Axis, v: f64| f64::from(axis.map(&v, (0, 10_000))) / 10_000.0;
    // Counts in the four corner boxes, each 40 % wide and 35 % high.
    let mut counts = [0usize; 4]; // upper-right, upper-left, lower-right, lower-left
    for &(px, py) in points {
        let (fx, fy) = (fraction(spec.x_spec(), px), fraction(spec.y_spec(), py));
        let right = fx > 0.6;
        let left = fx < 0.4;
        let upper = fy > 0.65;
        let lower = fy < 0.35;
        if upper && right {
            counts[0] += 1;
        }
        if upper && left {
            counts[1] += 1;
        }
        if lower && right {
            counts[2] += 1;
        }
        if lower && left {
            counts[3] += 1;
        }
    }
    let corners = [
        SeriesLabelPosition::UpperRight,
        SeriesLabelPosition::UpperLeft,
        SeriesLabelPosition::LowerRight,
        SeriesLabelPosition::LowerLeft,
    ];
    let best = (0..4).min_by_key(|&i| counts[i]).unwrap_or(0);
    corners[best].clone()
}
