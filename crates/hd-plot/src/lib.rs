//! Plots (SVG and PNG) for the workbench, drawn with plotters.
//!
//! Every function writes one figure to a path whose extension picks the format (`.svg`
//! or `.png`), creating the parent folder if needed and writing atomically. Inputs are
//! checked first: empty or all-NaN data is a [`PlotError`] naming the file, not a panic
//! and not an empty picture. NaN and infinite points are left out; axis ranges come from
//! the finite data, padded, and an all-equal range is widened. Tiny or huge tick values
//! get scientific labels (`3.0e-4`). Text uses DejaVu Sans embedded in the crate.
//!
//! Figures:
//! - [`response_plot`]: a run's load angle θz(t) and its torque–deflection loop Tb(θ);
//! - [`bode_plot`]: magnitude [dB] and phase [°] of frequency responses ([`BodeCurve`]);
//! - [`line_plot`] / [`overlay_plot`]: named curves with a legend, optional log x;
//! - [`heatmap`]: values on a grid with a colour bar, optional log axes;
//! - [`bar_chart`]: grouped bars ([`BarGroup`]) with optional error bars;
//! - [`fit_plot`] and [`residual_plot`]: measured points against a fitted curve, and the
//!   residuals.

mod axis;
mod bars;
mod bode;
mod chart;
mod colorbar;
mod colormap;
mod decimate;
mod error;
mod fit;
mod font;
mod grid;
mod heatmap;
mod lines;
mod output;
mod ranges;
mod raster;
mod response;
mod scatter;
mod series;
mod stream;
mod style;
mod ticks;

pub use bars::{BarGroup, bar_chart};
pub use bode::{BodeCurve, bode_plot};
pub use error::PlotError;
pub use fit::{fit_plot, residual_plot};
pub use heatmap::heatmap;
pub use lines::{line_plot, overlay_plot};
pub use response::response_plot;
pub use series::Series;
pub use stream::ThinnedCurve;
