//! Line plots: one or more named curves with a legend, optionally on a log x axis.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Axis;
use crate::chart::{self, Chart, Frame};
use crate::decimate;
use crate::error::PlotError;
use crate::output::{self, DrawError, Figure};
use crate::ranges;
use crate::series::{self, Drawable, Runs, Series};
use crate::style;

/// Draw broken-line `runs` in `color`; a run of one point is drawn as a dot. With a
/// `label`, the curve gets a legend entry. Long runs are decimated to the plot's pixels
/// first ([`crate::decimate`]), so the file's size does not grow with the data's.
pub(crate) fn draw_runs<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    runs: &[Vec<(f64, f64)>],
    color: RGBColor,
    label: Option<&str>,
) -> Result<(), DrawError> {
    let line = color.stroke_width(2);
    let mut lines: Vec<Vec<(f64, f64)>> = runs
        .iter()
        .filter(|r| r.len() > 1)
        .map(|r| decimate::envelope(r, |p| chart.backend_coord(p)))
        .collect();
    decimate::cap(&mut lines, decimate::MAX_VERTICES);
    let drawn = chart.draw_series(lines.into_iter().map(|r| PathElement::new(r, line)))?;
    if let Some(label) = label {
        drawn.label(label).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], line));
    }
    chart.draw_series(
        runs.iter().filter(|r| r.len() == 1).map(|r| Circle::new(r[0], 3, color.filled())),
    )?;
    Ok(())
}

/// A line figure ready to draw.
struct Lines<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    x: Axis,
    y: Axis,
    /// Legend name and drawable runs of each curve.
    curves: Vec<(String, Runs)>,
}

impl Figure for Lines<'_> {
    fn size(&self) -> (u32, u32) {
        style::SINGLE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let area = chart::titled(root, self.title)?;
        let frame = Frame::new(self.x_label, self.y_label);
        let mut chart = chart::framed(&area, frame, self.x.clone(), self.y.clone())?;
        for (i, (name, runs)) in self.curves.iter().enumerate() {
            draw_runs(&mut chart, runs, style::color(i), Some(name))?;
        }
        let all = self.curves.iter().flat_map(|c| c.1.iter().flatten());
        chart::legend(&mut chart, all)
    }
}

/// Plot each series as a line, with a legend of their names, and write it to `path`
/// (`.svg` or `.png`).
///
/// Axis labels should carry units, e.g. `"f [Hz]"`. With `log_x`, the x axis is
/// logarithmic and points with x ≤ 0 are left out. NaN or infinite points break a line.
/// A series with nothing drawable still gets a legend entry, marked "(no data)".
///
/// Errors: unsupported extension, no series, a series with empty x or with y of another
/// length, no drawable point in any series, or a failure to create or write the file.
pub fn line_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_x: bool,
) -> Result<(), PlotError> {
    output::check_path(path)?;
    if series.is_empty() {
        return Err(PlotError::EmptyInput {
            path: path.to_path_buf(),
            what: "the list of series".to_string(),
        });
    }
    let ok = Drawable { log_x, log_y: false };
    let mut curves = Vec::with_capacity(series.len());
    for s in series {
        let what = format!("series \"{}\"", s.name);
        series::check_pair(path, &what, &s.x, &s.y)?;
        let runs = series::runs(&s.x, &s.y, ok);
        let name = if runs.is_empty() { format!("{} (no data)", s.name) } else { s.name.clone() };
        curves.push((name, runs));
    }
    let Some(((x0, x1), (y0, y1))) = series::runs_extent(curves.iter().flat_map(|c| &c.1)) else {
        let x: Vec<f64> = series.iter().flat_map(|s| s.x.iter().copied()).collect();
        let y: Vec<f64> = series.iter().flat_map(|s| s.y.iter().copied()).collect();
        return Err(series::nothing_drawable(path, "every series", &x, &y, ok));
    };
    let (x0, x1) = if log_x { ranges::log_range(x0, x1) } else { ranges::linear_range(x0, x1) };
    let (y0, y1) = ranges::linear_range(y0, y1);
    let figure = Lines {
        title,
        x_label,
        y_label,
        x: Axis::new(x0, x1, log_x),
        y: Axis::linear(y0, y1),
        curves,
    };
    output::render(path, &figure)
}

/// Overlay one signal from several runs (one series per run, named after it) on linear
/// axes. The same drawing as [`line_plot`] without a log axis.
pub fn overlay_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    runs: &[Series],
) -> Result<(), PlotError> {
    line_plot(path, title, x_label, y_label, runs, false)
}
