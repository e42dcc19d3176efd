//! Bode figure: magnitude [dB] over phase [°], two stacked panels sharing one logarithmic
//! frequency axis, several curves with one legend.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Axis;
use crate::chart::{self, Frame};
use crate::error::PlotError;
use crate::lines::draw_runs;
use crate::output::{self, DrawError, Figure};
use crate::ranges;
use crate::series::{self, Drawable, Runs};
use crate::style;

/// One frequency response: magnitude and phase at each frequency.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BodeCurve {
    /// Legend text.
    pub name: String,
    /// Frequencies [Hz], positive.
    pub freq: Vec<f64>,
    /// Magnitude at each frequency [dB].
    pub mag_db: Vec<f64>,
    /// Phase at each frequency [°], already unwrapped by the caller.
    pub phase_deg: Vec<f64>,
}

/// The drawable runs of both panels of each curve.
struct Bode<'a> {
    title: &'a str,
    f: Axis,
    mag: Axis,
    phase: Axis,
    /// Legend name, magnitude runs and phase runs of each curve.
    curves: Vec<(String, Runs, Runs)>,
}

impl Figure for Bode<'_> {
    fn size(&self) -> (u32, u32) {
        style::STACKED
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let area = chart::titled(root, self.title)?;
        let (_, h) = area.dim_in_pixel();
        let (top, bottom) = area.split_vertically((h as f64 * 0.55) as u32);
        let frame = Frame::new("f [Hz]", "magnitude [dB]");
        let mut chart = chart::framed(&top, frame, self.f.clone(), self.mag.clone())?;
        for (i, (name, mag, _)) in self.curves.iter().enumerate() {
            draw_runs(&mut chart, mag, style::color(i), Some(name))?;
        }
        chart::legend(&mut chart, self.curves.iter().flat_map(|c| c.1.iter().flatten()))?;
        let frame = Frame::new("f [Hz]", "phase [°]");
        let mut chart = chart::framed(&bottom, frame, self.f.clone(), self.phase.clone())?;
        for (i, (_, _, phase)) in self.curves.iter().enumerate() {
            draw_runs(&mut chart, phase, style::color(i), None)?;
        }
        Ok(())
    }
}

/// Draw the Bode plot of `curves` to `path` (`.svg` or `.png`): magnitude [dB] on top,
/// phase [°] below, frequency [Hz] on a log axis shared by both. NaN points and
/// frequencies ≤ 0 are left out and break a line.
///
/// Errors: unsupported extension, no curves, a curve with no frequencies or with
/// magnitudes or phases of another length, no drawable point, or a failure to write.
pub fn bode_plot(path: &Path, title: &str, curves: &[BodeCurve]) -> Result<(), PlotError> {
    output::check_path(path)?;
    if curves.is_empty() {
        return Err(PlotError::EmptyInput {
            path: path.to_path_buf(),
            what: "the list of Bode curves".to_string(),
        });
    }
    let ok = Drawable { log_x: true, log_y: false };
    let mut drawn = Vec::with_capacity(curves.len());
    for c in curves {
        series::check_pair(path, &format!("magnitude of \"{}\"", c.name), &c.freq, &c.mag_db)?;
        series::check_pair(path, &format!("phase of \"{}\"", c.name), &c.freq, &c.phase_deg)?;
        let mag = series::runs(&c.freq, &c.mag_db, ok);
        let phase = series::runs(&c.freq, &c.phase_deg, ok);
        let name = if mag.is_empty() { format!("{} (no data)", c.name) } else { c.name.clone() };
        drawn.push((name, mag, phase));
    }
    let mag_extent = series::runs_extent(drawn.iter().flat_map(|c| &c.1));
    let phase_extent = series::runs_extent(drawn.iter().flat_map(|c| &c.2));
    let (Some(((f0, f1), (m0, m1))), Some((_, (p0, p1)))) = (mag_extent, phase_extent) else {
        let f: Vec<f64> = curves.iter().flat_map(|c| c.freq.iter().copied()).collect();
        let m: Vec<f64> = curves.iter().flat_map(|c| c.mag_db.iter().copied()).collect();
        return Err(series::nothing_drawable(path, "every Bode curve", &f, &m, ok));
    };
    let (f0, f1) = ranges::log_range(f0, f1);
    let (m0, m1) = ranges::linear_range(m0, m1);
    let (p0, p1) = ranges::linear_range(p0, p1);
    let figure = Bode {
        title,
        f: Axis::log(f0, f1),
        mag: Axis::linear(m0, m1),
        phase: Axis::linear(p0, p1),
        curves: drawn,
    };
    output::render(path, &figure)
}
