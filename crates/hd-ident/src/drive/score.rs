//! Scores of a simulated output against the measured one, as the benchmarks give them.

use serde::Serialize;

/// Relative error, RMSE and fit percentage of one output.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Score {
    /// ‖y − ŷ‖/‖y‖ [%].
    pub rel_error: f64,
    /// √(mean (y − ŷ)²) [output unit].
    pub rmse: f64,
    /// 100·(1 − ‖y − ŷ‖/‖y − ȳ‖) [%].
    pub fit_percent: f64,
}

/// Score `sim` against `meas` (same length).
pub fn score(meas: &[f64], sim: &[f64]) -> Score {
    let n = meas.len().max(1) as f64;
    let mean = meas.iter().sum::<f64>() / n;
    let err: f64 = meas.iter().zip(sim).map(|(y, s)| (y - s).powi(2)).sum::<f64>().sqrt();
    let norm: f64 = meas.iter().map(|y| y * y).sum::<f64>().sqrt();
    let spread: f64 = meas.iter().map(|y| (y - mean).powi(2)).sum::<f64>().sqrt();
    Score {
        rel_error: 100.0 * err / norm,
        rmse: err / n.sqrt(),
        fit_percent: 100.0 * (1.0 - err / spread),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_of_a_known_error() {
        // y = (1, −1, 1, −1), ŷ = y·0.9: error norm 0.2, ‖y‖ = 2, mean 0.
        let y = [1.0, -1.0, 1.0, -1.0];
        let s = score(&y, &y.map(|v| 0.9 * v));
        assert!((s.rel_error - 10.0).abs() < 1e-12);
        assert!((s.rmse - 0.1).abs() < 1e-12);
        assert!((s.fit_percent - 90.0).abs() < 1e-12);
    }
}
