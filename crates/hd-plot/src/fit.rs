//! Identification plots: measured points with the fitted curve over them, and residuals.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Axis;
use crate::chart::{self, Frame};
use crate::error::PlotError;
use crate::lines::draw_runs;
use crate::output::{self, DrawError, Figure};
use crate::ranges;
use crate::scatter::Cloud;
use crate::series::{self, Drawable, Runs, Series};
use crate::style;

/// Share of the canvas height given to the data panel when residuals are shown below.
const MAIN_SHARE: f64 = 0.64;

/// The residual panel: measured minus fitted, against x.
struct Residuals {
    y_label: String,
    y: Axis,
    cloud: Cloud,
    /// Smallest and largest x of the drawn residuals.
    x_extent: (f64, f64),
}

impl Residuals {
    /// Residuals `r` at `x`, or `None` if none is finite.
    fn new(y_label: &str, x: &[f64], r: &[f64]) -> Option<Residuals> {
        let cloud = Cloud::new(x, r);
        let (lo, hi) = ranges::extent(cloud.points.iter().map(|p| p.1))?;
        let x_extent = ranges::extent(cloud.points.iter().map(|p| p.0))?;
        // Keep zero in view so the reference line is always there.
        let (lo, hi) = ranges::linear_range(lo.min(0.0), hi.max(0.0));
        Some(Residuals {
            y_label: residual_label(y_label),
            y: Axis::linear(lo, hi),
            cloud,
            x_extent,
        })
    }

    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        x: &Axis,
        x_label: &str,
    ) -> Result<(), DrawError> {
        let frame = Frame::new(x_label, &self.y_label);
        let mut chart = chart::framed(area, frame, x.clone(), self.y.clone())?;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(x.lo(), 0.0), (x.hi(), 0.0)],
            BLACK.mix(0.6).stroke_width(1),
        )))?;
        self.cloud.draw(&mut chart, style::color(0), None)
    }
}

/// "residual [unit]" from an axis label "name [unit]".
fn residual_label(y_label: &str) -> String {
    match (y_label.rfind('['), y_label.ends_with(']')) {
        (Some(i), true) => format!("residual {}", &y_label[i..]),
        _ => format!("residual of {y_label}"),
    }
}

/// A fit figure ready to draw.
struct Fit<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    x: Axis,
    y: Axis,
    measured: Cloud,
    measured_name: String,
    fitted: Runs,
    fitted_name: String,
    residuals: Option<Residuals>,
}

impl Figure for Fit<'_> {
    fn size(&self) -> (u32, u32) {
        if self.residuals.is_some() { style::STACKED } else { style::SINGLE }
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let area = chart::titled(root, self.title)?;
        let (main, below) = match &self.residuals {
            Some(_) => {
                let split = (f64::from(area.dim_in_pixel().1) * MAIN_SHARE) as u32;
                let (top, bottom) = area.split_vertically(split);
                (top, Some(bottom))
            }
            None => (area, None),
        };
        // With residuals below, their panel carries the shared x description.
        let x_desc = if below.is_some() { "" } else { self.x_label };
        let frame = Frame::new(x_desc, self.y_label);
        let mut chart = chart::framed(&main, frame, self.x.clone(), self.y.clone())?;
        self.measured.draw(&mut chart, style::color(0), Some(&self.measured_name))?;
        draw_runs(&mut chart, &self.fitted, style::color(1), Some(&self.fitted_name))?;
        let all = self.measured.points.iter().chain(self.fitted.iter().flatten());
        chart::legend(&mut chart, all)?;
        if let (Some(residuals), Some(below)) = (&self.residuals, below) {
            residuals.draw(&below, &self.x, self.x_label)?;
        }
        Ok(())
    }
}

/// Whether `fitted` was evaluated at the measured abscissae (same count, same x where
/// both are finite), so that residuals can be formed sample by sample.
fn paired(measured: &Series, fitted: &Series) -> bool {
    measured.x.len() == fitted.x.len()
        && measured.x.iter().zip(&fitted.x).all(|(a, b)| {
            !(a.is_finite() && b.is_finite()) || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
        })
}

/// Plot measured points with the fitted curve over them and write it to `path` (`.svg`
/// or `.png`). The fitted series is drawn as a line in its own order (so a hysteresis loop
/// stays a loop). When `fitted` is given at the measured x values (same length, same x),
/// a residual panel (measured − fitted, labelled with the unit of `y_label`) is added
/// below. More than a few thousand measured points are thinned for drawing, and the legend
/// says so. The series names are the legend entries.
///
/// Errors: unsupported extension, an empty series or one with y of another length, no
/// finite point in either series, or a failure to create or write the file.
pub fn fit_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    measured: &Series,
    fitted: &Series,
) -> Result<(), PlotError> {
    output::check_path(path)?;
    let what_m = format!("measured series \"{}\"", measured.name);
    let what_f = format!("fitted series \"{}\"", fitted.name);
    series::check_pair(path, &what_m, &measured.x, &measured.y)?;
    series::check_pair(path, &what_f, &fitted.x, &fitted.y)?;
    let cloud = Cloud::new(&measured.x, &measured.y);
    if cloud.points.is_empty() {
        let lin = Drawable::LINEAR;
        return Err(series::nothing_drawable(path, &what_m, &measured.x, &measured.y, lin));
    }
    let runs = series::runs(&fitted.x, &fitted.y, Drawable::LINEAR);
    let Some((fx, fy)) = series::runs_extent(&runs) else {
        let lin = Drawable::LINEAR;
        return Err(series::nothing_drawable(path, &what_f, &fitted.x, &fitted.y, lin));
    };
    let mx = ranges::extent(cloud.points.iter().map(|p| p.0));
    let my = ranges::extent(cloud.points.iter().map(|p| p.1));
    let (x0, x1) = ranges::union(mx, Some(fx)).unwrap_or(fx);
    let (y0, y1) = ranges::union(my, Some(fy)).unwrap_or(fy);
    let (x0, x1) = ranges::linear_range(x0, x1);
    let (y0, y1) = ranges::linear_range(y0, y1);
    let residuals = if paired(measured, fitted) {
        let r: Vec<f64> = measured.y.iter().zip(&fitted.y).map(|(m, f)| m - f).collect();
        Residuals::new(y_label, &measured.x, &r)
    } else {
        None
    };
    let figure = Fit {
        title,
        x_label,
        y_label,
        x: Axis::linear(x0, x1),
        y: Axis::linear(y0, y1),
        measured_name: cloud.legend_name(&measured.name),
        measured: cloud,
        fitted: runs,
        fitted_name: fitted.name.clone(),
        residuals,
    };
    output::render(path, &figure)
}

/// A residual figure ready to draw.
struct ResidualFigure<'a> {
    title: &'a str,
    x_label: &'a str,
    x: Axis,
    residuals: Residuals,
}

impl Figure for ResidualFigure<'_> {
    fn size(&self) -> (u32, u32) {
        style::SINGLE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let area = chart::titled(root, self.title)?;
        self.residuals.draw(&area, &self.x, self.x_label)
    }
}

/// Plot residuals (`residuals.y`, e.g. measured − fitted) as points against
/// `residuals.x`, with a zero line, and write it to `path` (`.svg` or `.png`). `y_label`
/// is the label of the fitted quantity, e.g. `"Tb [N·m]"`; the axis reads
/// "residual [N·m]".
///
/// Errors: unsupported extension, an empty series or one with y of another length, no
/// finite point, or a failure to create or write the file.
pub fn residual_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    residuals: &Series,
) -> Result<(), PlotError> {
    output::check_path(path)?;
    let what = format!("residual series \"{}\"", residuals.name);
    series::check_pair(path, &what, &residuals.x, &residuals.y)?;
    let Some(panel) = Residuals::new(y_label, &residuals.x, &residuals.y) else {
        let lin = Drawable::LINEAR;
        return Err(series::nothing_drawable(path, &what, &residuals.x, &residuals.y, lin));
    };
    let (x0, x1) = ranges::linear_range(panel.x_extent.0, panel.x_extent.1);
    let figure = ResidualFigure { title, x_label, x: Axis::linear(x0, x1), residuals: panel };
    output::render(path, &figure)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn residual_label_keeps_unit() {
        assert_eq!(residual_label("Tb [N·m]"), "residual [N·m]");
        assert_eq!(residual_label("torque"), "residual of torque");
    }
}
