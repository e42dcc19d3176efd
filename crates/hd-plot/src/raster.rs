//! Rasters: a grid of many cells, or a cloud of many points, drawn as one image of the
//! plotting area (a PNG embedded in an SVG, or pixels of a PNG) rather than one element
//! per cell or point, so the file's size is set by the plot's pixels, not by the data.

use plotters::prelude::*;

use crate::colormap::ColorScale;

/// Grids with more cells than this are drawn as a raster (below it, one rectangle per
/// cell keeps them crisp at any zoom) [cells].
pub(crate) const RASTER_CELLS: usize = 4096;

/// The value at the centre of pixel `k` of `n` along an axis over `[lo, hi]` (log₁₀ spacing
/// on a log axis); `flip` counts pixels from the high end (image rows run downwards).
fn pixel_value(k: u32, n: u32, lo: f64, hi: f64, log: bool, flip: bool) -> f64 {
    let mut f = (f64::from(k) + 0.5) / f64::from(n.max(1));
    if flip {
        f = 1.0 - f;
    }
    if log { 10f64.powf(lo.log10() + f * (hi.log10() - lo.log10())) } else { lo + f * (hi - lo) }
}

/// The cell holding `v` given the cell edges (increasing), or `None` outside them.
fn cell_of(edges: &[f64], v: f64) -> Option<usize> {
    let n = edges.len().checked_sub(1)?;
    if !(v >= edges[0] && v <= edges[n]) {
        return None;
    }
    Some(edges.partition_point(|e| *e <= v).saturating_sub(1).min(n - 1))
}

/// RGB pixels (row-major from the top) of a `w` × `h` image of the cells: pixel centres
/// are mapped back to axis values, and each pixel takes the colour of the cell it falls in.
/// `values[iy * nx + ix]` is the cell between `x_edges[ix..=ix + 1]` and
/// `y_edges[iy..=iy + 1]`.
#[allow(clippy::too_many_arguments)] // Two axes, each with its edges and scale.
pub(crate) fn cells_image(
    (w, h): (u32, u32),
    x_edges: &[f64],
    y_edges: &[f64],
    log_x: bool,
    log_y: bool,
    values: &[f64],
    scale: ColorScale,
) -> Vec<u8> {
    let nx = x_edges.len() - 1;
    let (x0, x1) = (x_edges[0], x_edges[nx]);
    let (y0, y1) = (y_edges[0], y_edges[y_edges.len() - 1]);
    let cols: Vec<Option<usize>> =
        (0..w).map(|px| cell_of(x_edges, pixel_value(px, w, x0, x1, log_x, false))).collect();
    let mut out = vec![255u8; (w as usize) * (h as usize) * 3];
    for py in 0..h {
        let Some(iy) = cell_of(y_edges, pixel_value(py, h, y0, y1, log_y, true)) else {
            continue;
        };
        for (px, ix) in cols.iter().enumerate() {
            let Some(ix) = ix else { continue };
            let c = scale.color(values[iy * nx + ix]).rgb();
            let at = (py as usize * w as usize + px) * 3;
            out[at..at + 3].copy_from_slice(&[c.0, c.1, c.2]);
        }
    }
    out
}

/// Draw an RGB image covering the whole plotting area of `area`.
pub(crate) fn blit<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    (w, h): (u32, u32),
    pixels: Vec<u8>,
) -> Result<(), crate::output::DrawError> {
    if let Some(image) = BitMapElement::<(i32, i32)>::with_owned_buffer((0, 0), (w, h), pixels) {
        area.draw(&image)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_find_their_cells_on_linear_and_log_axes() {
        let edges = [0.0, 1.0, 2.0, 4.0];
        assert_eq!(cell_of(&edges, 0.5), Some(0));
        assert_eq!(cell_of(&edges, 1.0), Some(1));
        assert_eq!(cell_of(&edges, 4.0), Some(2));
        assert_eq!(cell_of(&edges, 4.5), None);
        // Log axis 1 … 100 over 2 pixels: centres at 10^0.5 and 10^1.5.
        let v = pixel_value(1, 2, 1.0, 100.0, true, false);
        assert!((v - 10f64.powf(1.5)).abs() < 1e-9);
        assert!((pixel_value(0, 2, 0.0, 1.0, false, true) - 0.75).abs() < 1e-12);
    }

    #[test]
    fn an_image_of_two_by_two_cells_puts_row_zero_at_the_bottom() {
        let scale = ColorScale { lo: 0.0, hi: 3.0 };
        let px = cells_image(
            (2, 2),
            &[0.0, 1.0, 2.0],
            &[0.0, 1.0, 2.0],
            false,
            false,
            &[0.0, 1.0, 2.0, 3.0],
            scale,
        );
        let at = |x: usize, y: usize| {
            let k = (y * 2 + x) * 3;
            (px[k], px[k + 1], px[k + 2])
        };
        let c = |v: f64| {
            let c = scale.color(v).rgb();
            (c.0, c.1, c.2)
        };
        // Top-left pixel is the cell at (x 0, y 1), value 2; bottom-right is value 1.
        assert_eq!(at(0, 0), c(2.0));
        assert_eq!(at(1, 1), c(1.0));
    }
}
