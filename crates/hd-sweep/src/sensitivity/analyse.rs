//! From a design's points and the metric values of its runs to the result table.
//!
//! This is the one step a study needs after its runs: the points can come in any order
//! (the tags carry the structure), a point missing from the list counts as a failed run,
//! and a NaN (or infinite) metric value is a failed run. A point may also stand in for a
//! run whose coordinates are unknown (a run missing from a results table, listed so that
//! its base row or trajectory is counted): give it non-finite unit coordinates and NaN
//! outputs, and its group is dropped like any other with a failed run.

use super::design::{Block, DesignPoint, PointTag, SensitivityMethod};
use super::error::{Result, SensitivityError};
use super::morris_effects::{MorrisStep, morris_statistics, trajectory_steps};
use super::result::SensitivityRow;
use super::sobol_indices::{SaltelliOutputs, SobolOptions, sobol_indices};

/// One metric's values, aligned with the design points (NaN = failed run).
#[derive(Clone, Copy, Debug)]
pub struct MetricColumn<'a> {
    /// Metric name, as it should appear in the result rows.
    pub name: &'a str,
    /// One value per design point, in the same order as the points.
    pub values: &'a [f64],
}

/// Sensitivity rows for every (metric, parameter) pair, metric by metric.
///
/// `parameters` names the coordinates of the points in order; `points` are the design
/// points that were run (all of one method); `metrics` their outputs. `options` applies to
/// Sobol' designs (Morris has no settings).
pub fn analyse<S: AsRef<str>>(
    parameters: &[S],
    points: &[DesignPoint],
    metrics: &[MetricColumn<'_>],
    options: &SobolOptions,
) -> Result<Vec<SensitivityRow>> {
    let dims = parameters.len();
    if dims == 0 {
        return Err(SensitivityError::NoParameters);
    }
    let first = points.first().ok_or(SensitivityError::EmptyDesign)?;
    let method = first.tag.method();
    for (index, p) in points.iter().enumerate() {
        if p.tag.method() != method {
            return Err(SensitivityError::MixedMethods);
        }
        if p.unit.len() != dims {
            return Err(SensitivityError::PointWidth { index, got: p.unit.len(), expected: dims });
        }
    }
    for m in metrics {
        if m.values.len() != points.len() {
            return Err(SensitivityError::MetricLength {
                metric: m.name.to_string(),
                got: m.values.len(),
                expected: points.len(),
            });
        }
    }
    let slots = slot_table(points, dims)?;
    let names: Vec<&str> = parameters.iter().map(AsRef::as_ref).collect();
    match method {
        SensitivityMethod::Sobol => Ok(sobol_rows(&names, &slots, metrics, options)),
        SensitivityMethod::Morris => morris_rows(&names, points, &slots, metrics),
    }
}

/// `table[group][slot]` = index of the point with that tag, if present. Groups are base rows
/// (Sobol': `dims + 2` slots) or trajectories (Morris: `dims + 1` slots).
fn slot_table(points: &[DesignPoint], dims: usize) -> Result<Vec<Vec<Option<usize>>>> {
    let groups = points.iter().map(|p| p.tag.to_parts(dims).1).max().map_or(0, |g| g + 1);
    let width = match points[0].tag.method() {
        SensitivityMethod::Sobol => dims + 2,
        SensitivityMethod::Morris => dims + 1,
    };
    let mut table = vec![vec![None; width]; groups];
    for (index, p) in points.iter().enumerate() {
        let (_, group, slot) = p.tag.to_parts(dims);
        let fits = match p.tag {
            PointTag::Sobol { block: Block::AB(i), .. } => i < dims,
            _ => slot < width,
        };
        if !fits {
            return Err(SensitivityError::TagOutOfRange { index, tag: p.tag.to_string(), dims });
        }
        let cell = &mut table[group][slot];
        if cell.is_some() {
            return Err(SensitivityError::DuplicateTag { index, tag: p.tag.to_string() });
        }
        *cell = Some(index);
    }
    Ok(table)
}

/// Value of a metric at an optional point; a missing point reads as a failed run.
fn value(values: &[f64], index: Option<usize>) -> f64 {
    index.map_or(f64::NAN, |i| values[i])
}

fn sobol_rows(
    names: &[&str],
    slots: &[Vec<Option<usize>>],
    metrics: &[MetricColumn<'_>],
    options: &SobolOptions,
) -> Vec<SensitivityRow> {
    let dims = names.len();
    let mut rows = Vec::with_capacity(metrics.len() * dims);
    for m in metrics {
        let column =
            |pos: usize| -> Vec<f64> { slots.iter().map(|g| value(m.values, g[pos])).collect() };
        let outputs = SaltelliOutputs {
            a: column(Block::A.position(dims)),
            b: column(Block::B.position(dims)),
            ab: (0..dims).map(|i| column(Block::AB(i).position(dims))).collect(),
        };
        let est = sobol_indices(&outputs, options);
        for (i, name) in names.iter().enumerate() {
            let mut row = SensitivityRow::empty(SensitivityMethod::Sobol, name, m.name);
            (row.s1, row.s1_lo, row.s1_hi) = (est.s1[i].value, est.s1[i].lo, est.s1[i].hi);
            (row.st, row.st_lo, row.st_hi) = (est.st[i].value, est.st[i].lo, est.st[i].hi);
            (row.n_used, row.n_dropped, row.note) = (est.n_used, est.n_dropped, est.note.clone());
            rows.push(row);
        }
    }
    rows
}

fn morris_rows(
    names: &[&str],
    points: &[DesignPoint],
    slots: &[Vec<Option<usize>>],
    metrics: &[MetricColumn<'_>],
) -> Result<Vec<SensitivityRow>> {
    // Steps of every complete trajectory; the structure is checked once, for all metrics.
    let steps: Vec<Option<(Vec<usize>, Vec<MorrisStep>)>> = slots
        .iter()
        .enumerate()
        .map(|(t, group)| {
            let Some(idx) = group.iter().copied().collect::<Option<Vec<usize>>>() else {
                return Ok(None);
            };
            // A stand-in for a missing run has no coordinates: the trajectory is incomplete.
            if idx.iter().any(|&i| points[i].unit.iter().any(|u| !u.is_finite())) {
                return Ok(None);
            }
            let unit: Vec<&[f64]> = idx.iter().map(|&i| points[i].unit.as_slice()).collect();
            Ok(Some((idx, trajectory_steps(t, &unit)?)))
        })
        .collect::<Result<_>>()?;
    let mut rows = Vec::with_capacity(metrics.len() * names.len());
    for m in metrics {
        let ys: Vec<Option<Vec<f64>>> = steps
            .iter()
            .map(|s| s.as_ref().map(|(idx, _)| idx.iter().map(|&i| m.values[i]).collect()))
            .collect();
        let input: Vec<Option<(&[MorrisStep], &[f64])>> = steps
            .iter()
            .zip(&ys)
            .map(|(s, y)| match (s, y) {
                (Some((_, st)), Some(y)) => Some((st.as_slice(), y.as_slice())),
                _ => None,
            })
            .collect();
        let est = morris_statistics(names.len(), &input);
        for (i, name) in names.iter().enumerate() {
            let mut row = SensitivityRow::empty(SensitivityMethod::Morris, name, m.name);
            (row.mu, row.mu_star, row.sigma) = (est.mu[i], est.mu_star[i], est.sigma[i]);
            (row.n_used, row.n_dropped, row.note) = (est.n_used, est.n_dropped, est.note.clone());
            rows.push(row);
        }
    }
    Ok(rows)
}
