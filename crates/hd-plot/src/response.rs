//! The response of one run: load angle against time beside the torque–deflection loop.

use std::path::Path;

use hd_model::Trace;
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

/// One panel: axes, labels and the curve's runs.
struct Panel {
    caption: &'static str,
    x_label: &'static str,
    y_label: &'static str,
    x: Axis,
    y: Axis,
    runs: Runs,
}

impl Panel {
    /// A panel of `y` against `x`, or the error if nothing in it can be drawn.
    fn new(
        path: &Path,
        (caption, x_label, y_label): (&'static str, &'static str, &'static str),
        (x_name, x): (&str, &[f64]),
        (y_name, y): (&str, &[f64]),
    ) -> Result<Panel, PlotError> {
        let runs = series::runs(x, y, Drawable::LINEAR);
        let Some(((x0, x1), (y0, y1))) = series::runs_extent(&runs) else {
            let what = format!("trace columns {x_name} and {y_name}");
            return Err(series::nothing_drawable(path, &what, x, y, Drawable::LINEAR));
        };
        let (x0, x1) = ranges::linear_range(x0, x1);
        let (y0, y1) = ranges::linear_range(y0, y1);
        Ok(Panel {
            caption,
            x_label,
            y_label,
            x: Axis::linear(x0, x1),
            y: Axis::linear(y0, y1),
            runs,
        })
    }

    fn draw<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let frame = Frame::new(self.x_label, self.y_label).caption(self.caption);
        let mut chart = chart::framed(area, frame, self.x.clone(), self.y.clone())?;
        draw_runs(&mut chart, &self.runs, style::color(0), None)
    }
}

/// The two-panel response figure.
struct Response<'a> {
    title: &'a str,
    angle: Panel,
    hysteresis: Panel,
}

impl Figure for Response<'_> {
    fn size(&self) -> (u32, u32) {
        style::SIDE_BY_SIDE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let area = chart::titled(root, self.title)?;
        let panels = area.split_evenly((1, 2));
        self.angle.draw(&panels[0])?;
        self.hysteresis.draw(&panels[1])
    }
}

/// Plot a run's response and write it to `path` (`.svg` or `.png`): on the left the load
/// angle θz [rad] against time t [s], on the right the transmitted torque Tb [N·m]
/// against the gear deflection θ [rad] (the hysteresis loop).
///
/// Errors: unsupported extension, an empty trace, a column of another length than `t`,
/// no finite point in a panel, or a failure to create or write the file.
pub fn response_plot(path: &Path, trace: &Trace, title: &str) -> Result<(), PlotError> {
    output::check_path(path)?;
    if trace.is_empty() {
        return Err(PlotError::EmptyInput {
            path: path.to_path_buf(),
            what: "the trace".to_string(),
        });
    }
    for (name, column) in [("theta_z", &trace.theta_z), ("theta", &trace.theta), ("Tb", &trace.tb)]
    {
        if column.len() != trace.len() {
            return Err(PlotError::LengthMismatch {
                path: path.to_path_buf(),
                what: format!("trace column {name} (one per time sample)"),
                expected: trace.len(),
                found: column.len(),
            });
        }
    }
    let angle = Panel::new(
        path,
        ("Load angle", "t [s]", "θz [rad]"),
        ("t", &trace.t),
        ("theta_z", &trace.theta_z),
    )?;
    let hysteresis = Panel::new(
        path,
        ("Torque–deflection loop", "θ [rad]", "Tb [N·m]"),
        ("theta", &trace.theta),
        ("Tb", &trace.tb),
    )?;
    let figure = Response { title, angle, hysteresis };
    output::render(path, &figure)
}
