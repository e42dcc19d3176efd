//! Named x–y data and the checks every x–y plot applies to it.

use std::path::Path;

use crate::error::PlotError;

/// One named curve: `y[i]` against `x[i]`, in the units of the plot's axis labels.
/// NaN or infinite points are left out (a line is broken there).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Abscissae [x-axis unit].
    pub x: Vec<f64>,
    /// Ordinates [y-axis unit]; same length as `x`.
    pub y: Vec<f64>,
}

impl Series {
    /// A series from its parts.
    pub fn new(name: impl Into<String>, x: Vec<f64>, y: Vec<f64>) -> Self {
        Series { name: name.into(), x, y }
    }
}

/// Unbroken runs of drawable points of one curve [axis units].
pub(crate) type Runs = Vec<Vec<(f64, f64)>>;

/// Which points can be drawn on the chosen axes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Drawable {
    /// The x axis is logarithmic (x must be positive).
    pub log_x: bool,
    /// The y axis is logarithmic (y must be positive).
    pub log_y: bool,
}

impl Drawable {
    /// Both axes linear.
    pub(crate) const LINEAR: Drawable = Drawable { log_x: false, log_y: false };

    /// Whether the point `(x, y)` can be placed.
    pub(crate) fn accepts(self, x: f64, y: f64) -> bool {
        x.is_finite() && y.is_finite() && (!self.log_x || x > 0.0) && (!self.log_y || y > 0.0)
    }
}

/// The drawable points of `x`, `y` as unbroken runs: a point that cannot be drawn ends
/// a run, so lines never bridge missing data.
pub(crate) fn runs(x: &[f64], y: &[f64], ok: Drawable) -> Runs {
    let mut out = Vec::new();
    let mut current = Vec::new();
    for (&xi, &yi) in x.iter().zip(y) {
        if ok.accepts(xi, yi) {
            current.push((xi, yi));
        } else if !current.is_empty() {
            out.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        out.push(current);
    }
    out
}

/// Check that `x` and `y` (described as `what`) are non-empty and of equal length.
pub(crate) fn check_pair(path: &Path, what: &str, x: &[f64], y: &[f64]) -> Result<(), PlotError> {
    if x.is_empty() {
        return Err(PlotError::EmptyInput {
            path: path.to_path_buf(),
            what: format!("x of {what}"),
        });
    }
    if y.len() != x.len() {
        return Err(PlotError::LengthMismatch {
            path: path.to_path_buf(),
            what: format!("y of {what} (one per x)"),
            expected: x.len(),
            found: y.len(),
        });
    }
    Ok(())
}

/// The error for `what` having no point that can be drawn on the chosen axes.
pub(crate) fn nothing_drawable(
    path: &Path,
    what: &str,
    x: &[f64],
    y: &[f64],
    ok: Drawable,
) -> PlotError {
    let any_finite = x.iter().zip(y).any(|(a, b)| a.is_finite() && b.is_finite());
    if any_finite && (ok.log_x || ok.log_y) {
        PlotError::NoPositiveData { path: path.to_path_buf(), what: what.to_string() }
    } else {
        PlotError::NoFiniteData { path: path.to_path_buf(), what: what.to_string() }
    }
}

/// Smallest and largest x and y over all the runs.
pub(crate) fn runs_extent<'a>(
    runs: impl IntoIterator<Item = &'a Vec<(f64, f64)>>,
) -> Option<((f64, f64), (f64, f64))> {
    let mut xs = None;
    let mut ys = None;
    for run in runs {
        xs = crate::ranges::union(xs, crate::ranges::extent(run.iter().map(|p| p.0)));
        ys = crate::ranges::union(ys, crate::ranges::extent(run.iter().map(|p| p.1)));
    }
    Some((xs?, ys?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_break_at_missing_points() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let y = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY];
        let r = runs(&x, &y, Drawable::LINEAR);
        assert_eq!(r, vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]);
        let log = Drawable { log_x: true, log_y: false };
        assert_eq!(runs(&x, &y, log)[0], vec![(2.0, 2.0), (3.0, 3.0)]);
    }
}
