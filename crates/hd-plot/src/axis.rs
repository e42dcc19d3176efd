//! One coordinate type for every axis of the crate: linear, logarithmic, or categorical.
//! Keeping a single type lets every plot share one chart helper whatever its scales, and
//! lets the axis format its own tick labels (see [`crate::ticks`]).

use std::ops::Range;

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};

use crate::ticks;

/// Number of labelled ticks asked for on each axis.
pub(crate) const LABELS: usize = 9;

/// How values are placed along the axis.
#[derive(Clone, Debug, PartialEq)]
enum Scale {
    Linear,
    Log,
    /// Category `i` sits at value `i`; the names label the ticks.
    Categories(Vec<String>),
}

/// A plotting axis over `[lo, hi]`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Axis {
    lo: f64,
    hi: f64,
    scale: Scale,
}

impl Axis {
    /// A linear axis over `[lo, hi]` (`lo < hi`).
    pub(crate) fn linear(lo: f64, hi: f64) -> Self {
        Axis { lo, hi, scale: Scale::Linear }
    }

    /// A log axis over `[lo, hi]` (`0 < lo < hi`).
    pub(crate) fn log(lo: f64, hi: f64) -> Self {
        Axis { lo, hi, scale: Scale::Log }
    }

    /// A linear or log axis, as asked.
    pub(crate) fn new(lo: f64, hi: f64, log: bool) -> Self {
        if log { Self::log(lo, hi) } else { Self::linear(lo, hi) }
    }

    /// An axis with one slot per name, category `i` centred on value `i`.
    pub(crate) fn categories(names: &[String]) -> Self {
        Axis { lo: -0.5, hi: names.len() as f64 - 0.5, scale: Scale::Categories(names.to_vec()) }
    }

    /// Lower end of the axis.
    pub(crate) fn lo(&self) -> f64 {
        self.lo
    }

    /// Upper end of the axis.
    pub(crate) fn hi(&self) -> f64 {
        self.hi
    }

    /// Step between labelled ticks of a linear axis.
    fn label_step(&self) -> f64 {
        ticks::nice_step(self.lo, self.hi, LABELS)
    }
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let (a, b, v) = match self.scale {
            Scale::Log => (self.lo.log10(), self.hi.log10(), value.log10()),
            _ => (self.lo, self.hi, *value),
        };
        let fraction = (v - a) / (b - a);
        // Far-off or undefined values are pinned just outside the frame, never wrapped.
        let fraction = if fraction.is_nan() { 0.0 } else { fraction.clamp(-10.0, 11.0) };
        limit.0 + (fraction * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.max_num_points() == 0 {
            return Vec::new();
        }
        let minor = hint.weight().allow_light_points();
        match &self.scale {
            Scale::Linear => {
                let bold = ticks::nice_step(self.lo, self.hi, hint.bold_points());
                let step = if minor { bold / 5.0 } else { bold };
                let points = ticks::linear_ticks(self.lo, self.hi, step);
                if points.len() <= hint.max_num_points() {
                    points
                } else {
                    ticks::linear_ticks(self.lo, self.hi, bold)
                }
            }
            Scale::Log => ticks::log_ticks(self.lo, self.hi, hint.max_num_points(), minor),
            Scale::Categories(names) if !minor => (0..names.len()).map(|i| i as f64).collect(),
            Scale::Categories(_) => Vec::new(),
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format_ext(&self, value: &f64) -> String {
        match &self.scale {
            Scale::Linear => {
                let magnitude = self.lo.abs().max(self.hi.abs());
                ticks::linear_label(*value, self.label_step(), magnitude)
            }
            Scale::Log => ticks::log_label(*value, self.lo, self.hi),
            Scale::Categories(names) => {
                let i = value.round();
                if i >= 0.0 && (i as usize) < names.len() {
                    names[i as usize].clone()
                } else {
                    String::new()
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::coord::ranged1d::BoldPoints;

    #[test]
    fn maps_linear_and_log() {
        let lin = Axis::linear(0.0, 10.0);
        assert_eq!(lin.map(&5.0, (0, 100)), 50);
        let log = Axis::log(1.0, 100.0);
        assert_eq!(log.map(&10.0, (0, 100)), 50);
        assert_eq!(log.map(&-1.0, (0, 100)), 0);
    }

    #[test]
    fn category_ticks_carry_names() {
        let names = vec!["a".to_string(), "b".to_string()];
        let axis = Axis::categories(&names);
        assert_eq!(axis.key_points(BoldPoints(8)), vec![0.0, 1.0]);
        assert_eq!(axis.format_ext(&1.0), "b");
    }

    #[test]
    fn tiny_axis_labels_are_scientific() {
        let axis = Axis::linear(-1e-4, 3.2e-4);
        let labels: Vec<String> =
            axis.key_points(BoldPoints(LABELS)).iter().map(|v| axis.format_ext(v)).collect();
        assert!(labels.contains(&"3.0e-4".to_string()), "{labels:?}");
    }
}
