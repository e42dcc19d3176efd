//! Heatmaps: one coloured cell per grid point, with a colour bar. Grids of more than
//! [`raster::RASTER_CELLS`] cells are drawn as one image of the plotting area.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Axis;
use crate::chart::{self, Frame};
use crate::colorbar;
use crate::colormap::ColorScale;
use crate::error::PlotError;
use crate::grid;
use crate::output::{self, DrawError, Figure};
use crate::ranges;
use crate::raster;
use crate::style;

/// Width of the colour-bar strip at the right of the canvas [px].
const COLORBAR_PX: u32 = 190;

/// A heatmap ready to draw.
struct Heatmap<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    /// Cell edges along x (nx + 1) and y (ny + 1).
    x_edges: Vec<f64>,
    y_edges: Vec<f64>,
    log_x: bool,
    log_y: bool,
    values: &'a [f64],
    scale: ColorScale,
    /// Colour-bar label, with the note on missing values if there are any.
    bar_label: String,
}

impl Figure for Heatmap<'_> {
    fn size(&self) -> (u32, u32) {
        style::SINGLE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let area = chart::titled(root, self.title)?;
        let width = area.dim_in_pixel().0;
        let (main, bar) = area.split_horizontally(width.saturating_sub(COLORBAR_PX));
        let (nx, ny) = (self.x_edges.len() - 1, self.y_edges.len() - 1);
        let x = Axis::new(self.x_edges[0], self.x_edges[nx], self.log_x);
        let y = Axis::new(self.y_edges[0], self.y_edges[ny], self.log_y);
        let mut chart = chart::framed(&main, Frame::new(self.x_label, self.y_label), x, y)?;
        if nx * ny > raster::RASTER_CELLS {
            // One image of the plotting area: the file's size is set by pixels, not cells.
            let plot = chart.plotting_area().strip_coord_spec();
            let size = plot.dim_in_pixel();
            let pixels = raster::cells_image(
                size,
                &self.x_edges,
                &self.y_edges,
                self.log_x,
                self.log_y,
                self.values,
                self.scale,
            );
            raster::blit(&plot, size, pixels)?;
            return colorbar::draw(&bar, self.scale, &self.bar_label);
        }
        chart.draw_series((0..ny).flat_map(|iy| {
            (0..nx).map(move |ix| {
                let corners = [
                    (self.x_edges[ix], self.y_edges[iy]),
                    (self.x_edges[ix + 1], self.y_edges[iy + 1]),
                ];
                let color = self.scale.color(self.values[iy * nx + ix]);
                Rectangle::new(corners, color.filled())
            })
        }))?;
        colorbar::draw(&bar, self.scale, &self.bar_label)
    }
}

/// Draw values on a grid as coloured cells, with a colour bar, and write it to `path`
/// (`.svg` or `.png`).
///
/// `xs` (nx) and `ys` (ny) are the cell centres [axis units], finite and strictly
/// increasing; `values` holds nx·ny values row by row, `values[iy * nx + ix]` at
/// `(xs[ix], ys[iy])`. Cells reach halfway to their neighbours (halfway in log₁₀ on a log
/// axis, which suits log-spaced grids). The colour scale spans the finite values; NaN or
/// infinite cells are drawn grey and the colour-bar label says so. `color_label` names the
/// value with its unit.
///
/// Errors: unsupported extension, an empty or invalid grid axis (non-finite, not
/// increasing, or ≤ 0 on a log axis), `values` of a length other than nx·ny, no finite
/// value, or a failure to create or write the file.
#[allow(clippy::too_many_arguments)] // The signature is the crate's public contract.
pub fn heatmap(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    xs: &[f64],
    ys: &[f64],
    values: &[f64],
    color_label: &str,
    log_x: bool,
    log_y: bool,
) -> Result<(), PlotError> {
    output::check_path(path)?;
    grid::check_centres(path, "heatmap xs", xs, log_x)?;
    grid::check_centres(path, "heatmap ys", ys, log_y)?;
    let cells = xs.len() * ys.len();
    if values.len() != cells {
        return Err(PlotError::LengthMismatch {
            path: path.to_path_buf(),
            what: format!("heatmap values ({} xs × {} ys)", xs.len(), ys.len()),
            expected: cells,
            found: values.len(),
        });
    }
    let Some((lo, hi)) = ranges::finite_extent(values) else {
        return Err(PlotError::NoFiniteData {
            path: path.to_path_buf(),
            what: "heatmap values".to_string(),
        });
    };
    let bar_label = if values.iter().all(|v| v.is_finite()) {
        color_label.to_string()
    } else {
        format!("{color_label}  (grey: NaN)")
    };
    let figure = Heatmap {
        title,
        x_label,
        y_label,
        x_edges: grid::edges(xs, log_x),
        y_edges: grid::edges(ys, log_y),
        log_x,
        log_y,
        values,
        scale: ColorScale { lo, hi },
        bar_label,
    };
    output::render(path, &figure)
}
