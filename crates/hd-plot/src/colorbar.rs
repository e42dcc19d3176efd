//! The colour bar beside a heatmap: the ramp from the smallest to the largest value, with
//! ticks and a label on its right.

use plotters::chart::LabelAreaPosition;
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::{Axis, LABELS};
use crate::colormap::{ColorScale, ramp};
use crate::output::DrawError;
use crate::style;

/// Number of uniform stripes the ramp is drawn with.
const STRIPES: usize = 256;

/// Draw a colour bar for `scale` on `area`, labelled `label`. The top and bottom margins
/// match those of [`crate::chart::framed`], so the bar lines up with the plot beside it.
pub(crate) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    scale: ColorScale,
    label: &str,
) -> Result<(), DrawError> {
    let (lo, hi) = crate::ranges::widen(scale.lo, scale.hi);
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_left(4)
        .set_label_area_size(LabelAreaPosition::Bottom, 60)
        .set_label_area_size(LabelAreaPosition::Right, 110)
        .build_cartesian_2d(Axis::linear(0.0, 1.0), Axis::linear(lo, hi))?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .x_labels(0)
        .y_labels(LABELS)
        .y_desc(label)
        .label_style(style::text(style::TICK_PX))
        .axis_desc_style(style::text(style::AXIS_LABEL_PX))
        .draw()?;
    let step = (hi - lo) / STRIPES as f64;
    let uniform = scale.hi <= scale.lo;
    chart.draw_series((0..STRIPES).map(|k| {
        let v0 = lo + k as f64 * step;
        let color = if uniform { ramp(0.5) } else { ramp((k as f64 + 0.5) / STRIPES as f64) };
        Rectangle::new([(0.0, v0), (1.0, v0 + step)], color.filled())
    }))?;
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, lo), (1.0, hi)],
        BLACK.stroke_width(1),
    )))?;
    Ok(())
}
