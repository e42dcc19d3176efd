//! Grouped bar charts: categories along x, one coloured bar per group in each category,
//! with optional error bars.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::axis::Axis;
use crate::chart::{self, Frame};
use crate::error::PlotError;
use crate::output::{self, DrawError, Figure};
use crate::ranges;
use crate::style;

/// Fraction of a category slot the bars of all groups fill together.
const FILL: f64 = 0.8;

/// One group of bars: a value for every category, drawn in one colour.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BarGroup {
    /// Legend text.
    pub name: String,
    /// Bar heights [y-axis unit], one per category; a NaN value leaves its bar out.
    pub values: Vec<f64>,
    /// Optional error bars `(lo, hi)` [y-axis unit], one per category; a pair with a
    /// non-finite end is left out.
    pub intervals: Option<Vec<(f64, f64)>>,
}

/// One bar ready to draw.
struct Bar {
    /// Left and right edge [category units].
    left: f64,
    right: f64,
    value: f64,
    interval: Option<(f64, f64)>,
}

impl Bar {
    fn centre(&self) -> f64 {
        0.5 * (self.left + self.right)
    }
}

/// A bar chart ready to draw.
struct Bars<'a> {
    title: &'a str,
    y_label: &'a str,
    x: Axis,
    y: Axis,
    /// Legend name and bars of each group.
    groups: Vec<(String, Vec<Bar>)>,
    width: u32,
}

impl Figure for Bars<'_> {
    fn size(&self) -> (u32, u32) {
        (self.width, style::SINGLE.1)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let area = chart::titled(root, self.title)?;
        let frame = Frame { x_grid: false, ..Frame::new("", self.y_label) };
        let mut chart = chart::framed(&area, frame, self.x.clone(), self.y.clone())?;
        for (g, (name, bars)) in self.groups.iter().enumerate() {
            let fill = style::color(g).filled();
            chart
                .draw_series(
                    bars.iter().map(|b| Rectangle::new([(b.left, 0.0), (b.right, b.value)], fill)),
                )?
                .label(name.as_str())
                .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 18, y + 6)], fill));
        }
        let whisker = BLACK.stroke_width(2);
        for (_, bars) in &self.groups {
            for b in bars {
                let Some((lo, hi)) = b.interval else { continue };
                let (c, cap) = (b.centre(), 0.25 * (b.right - b.left));
                chart.draw_series([
                    PathElement::new(vec![(c, lo), (c, hi)], whisker),
                    PathElement::new(vec![(c - cap, lo), (c + cap, lo)], whisker),
                    PathElement::new(vec![(c - cap, hi), (c + cap, hi)], whisker),
                ])?;
            }
        }
        // Bars occupy everything from the axis to their tops: keep the legend off them.
        let occupied: Vec<(f64, f64)> = self
            .groups
            .iter()
            .flat_map(|g| g.1.iter())
            .flat_map(|b| {
                let top = b.interval.map_or(b.value, |(lo, hi)| b.value.max(lo).max(hi));
                [0.0, 0.25, 0.5, 0.75, 1.0].map(|f| (b.centre(), f * top))
            })
            .collect();
        chart::legend(&mut chart, &occupied)
    }
}

/// Draw a grouped bar chart and write it to `path` (`.svg` or `.png`).
///
/// Each category is a slot along x (its name is the tick label); each group puts one bar
/// of its colour in every slot, with an error bar from `lo` to `hi` when `intervals` is
/// given. The y axis always includes zero; `y_label` names the value with its unit.
/// The canvas widens with the number of bars. Long category names may crowd each other.
///
/// Errors: unsupported extension, no categories or no groups, a group whose `values` or
/// `intervals` are not one per category, no finite value at all, or a failure to create
/// or write the file.
pub fn bar_chart(
    path: &Path,
    title: &str,
    y_label: &str,
    categories: &[String],
    groups: &[BarGroup],
) -> Result<(), PlotError> {
    output::check_path(path)?;
    let empty =
        |what: &str| PlotError::EmptyInput { path: path.to_path_buf(), what: what.to_string() };
    if categories.is_empty() {
        return Err(empty("the list of categories"));
    }
    if groups.is_empty() {
        return Err(empty("the list of bar groups"));
    }
    let n = categories.len();
    let width = FILL / groups.len() as f64;
    let mut drawn = Vec::with_capacity(groups.len());
    for (g, group) in groups.iter().enumerate() {
        let mismatch = |what: &str, found: usize| PlotError::LengthMismatch {
            path: path.to_path_buf(),
            what: format!("{what} of bar group \"{}\" (one per category)", group.name),
            expected: n,
            found,
        };
        if group.values.len() != n {
            return Err(mismatch("values", group.values.len()));
        }
        if let Some(iv) = &group.intervals
            && iv.len() != n
        {
            return Err(mismatch("intervals", iv.len()));
        }
        let bars: Vec<Bar> = group
            .values
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .map(|(i, &value)| {
                let left = i as f64 - 0.5 * FILL + g as f64 * width;
                let interval = group
                    .intervals
                    .as_ref()
                    .map(|iv| iv[i])
                    .filter(|(lo, hi)| lo.is_finite() && hi.is_finite());
                Bar { left: left + 0.05 * width, right: left + 0.95 * width, value, interval }
            })
            .collect();
        drawn.push((group.name.clone(), bars));
    }
    let tops = drawn.iter().flat_map(|g| g.1.iter()).flat_map(|b| {
        let (lo, hi) = b.interval.unwrap_or((b.value, b.value));
        [b.value, lo, hi]
    });
    let Some((lo, hi)) = ranges::extent(tops) else {
        return Err(PlotError::NoFiniteData {
            path: path.to_path_buf(),
            what: "every bar group".to_string(),
        });
    };
    let (lo, hi) = ranges::linear_range(lo.min(0.0), hi.max(0.0));
    let bar_count = (n * groups.len()) as u32;
    let figure = Bars {
        title,
        y_label,
        x: Axis::categories(categories),
        y: Axis::linear(lo, hi),
        groups: drawn,
        width: (140 + 28 * bar_count + 40 * n as u32).clamp(style::SINGLE.0, 4000),
    };
    output::render(path, &figure)
}
