//! Point clouds: measured samples drawn as dots, thinned to a bounded number of markers.

use plotters::prelude::*;

use crate::chart::Chart;
use crate::output::DrawError;

/// Most markers drawn for one point cloud; larger clouds are thinned by a fixed stride.
const MAX_MARKERS: usize = 4000;

/// Drawable points of a cloud, already thinned, and the stride used.
pub(crate) struct Cloud {
    /// The points kept [axis units].
    pub points: Vec<(f64, f64)>,
    /// Every `stride`-th drawable point was kept (1 = all).
    pub stride: usize,
}

impl Cloud {
    /// The finite points of `x`, `y`, thinned to at most [`MAX_MARKERS`].
    pub(crate) fn new(x: &[f64], y: &[f64]) -> Cloud {
        let finite: Vec<(f64, f64)> = x
            .iter()
            .zip(y)
            .map(|(&a, &b)| (a, b))
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .collect();
        let stride = finite.len().div_ceil(MAX_MARKERS).max(1);
        let points = finite.into_iter().step_by(stride).collect();
        Cloud { points, stride }
    }

    /// Legend text for a cloud called `name`, saying if it was thinned.
    pub(crate) fn legend_name(&self, name: &str) -> String {
        match self.stride {
            1 => name.to_string(),
            k => format!("{name} (1 in {k} points shown)"),
        }
    }

    /// Draw the points as dots of `color`, with a legend entry if `label` is given.
    pub(crate) fn draw<DB: DrawingBackend>(
        &self,
        chart: &mut Chart<'_, DB>,
        color: RGBColor,
        label: Option<&str>,
    ) -> Result<(), DrawError> {
        let dot = color.mix(0.7).filled();
        let drawn = chart.draw_series(self.points.iter().map(|&p| Circle::new(p, 3, dot)))?;
        if let Some(label) = label {
            drawn.label(label).legend(move |(x, y)| Circle::new((x + 12, y), 4, dot));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_clouds_are_thinned() {
        let x: Vec<f64> = (0..10_000).map(f64::from).collect();
        let cloud = Cloud::new(&x, &x);
        assert!(cloud.points.len() <= MAX_MARKERS);
        assert_eq!(cloud.stride, 3);
        assert_eq!(cloud.legend_name("measured"), "measured (1 in 3 points shown)");
    }
}
