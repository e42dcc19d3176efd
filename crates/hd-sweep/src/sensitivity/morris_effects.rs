//! Morris elementary effects and their statistics μ, μ*, σ.
//!
//! For the step of a trajectory that moves parameter `i` from unit coordinate `u` to
//! `u + δ` (δ = ±Δ), the elementary effect is
//! `EE_i = (y(after) − y(before)) / δ`.
//! Coordinates are unit-cube coordinates, so an effect is **the output change per full
//! range of the parameter** (linear or log scale, as set in its [`super::ParamRange`]), in
//! the metric's unit. This makes effects of parameters with different units comparable.
//!
//! Over the trajectories used: `μ_i` is the mean of `EE_i`, `μ*_i` the mean of `|EE_i|`
//! (Campolongo, Cariboni & Saltelli 2007), and `σ_i` the sample standard deviation of
//! `EE_i` (divisor r − 1), which flags interactions and nonlinearity.
//!
//! **Failed runs.** A trajectory with a non-finite output at any of its points is dropped
//! whole (its effects are chained, so a partial trajectory would favour the parameters
//! moved before the failure) and counted.

use super::error::{Result, SensitivityError};
use super::stats::{mean, sample_std};
use serde::{Deserialize, Serialize};

/// One step of a trajectory: which parameter moved and by how much.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MorrisStep {
    /// Index of the parameter that moved.
    pub parameter: usize,
    /// Signed change of its unit coordinate (±Δ in a standard design).
    pub delta: f64,
}

/// Read the steps of one trajectory from its points' unit coordinates (in step order).
/// Fails unless consecutive points differ in exactly one coordinate.
pub fn trajectory_steps(trajectory: usize, unit: &[&[f64]]) -> Result<Vec<MorrisStep>> {
    unit.windows(2)
        .enumerate()
        .map(|(s, w)| {
            let changed: Vec<usize> = (0..w[0].len()).filter(|&k| w[0][k] != w[1][k]).collect();
            match changed[..] {
                [k] => Ok(MorrisStep { parameter: k, delta: w[1][k] - w[0][k] }),
                _ => Err(SensitivityError::NotOneAtATime {
                    trajectory,
                    step: s + 1,
                    changed: changed.len(),
                }),
            }
        })
        .collect()
}

/// μ, μ*, σ of one metric, per parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MorrisEstimate {
    /// Mean elementary effect [metric unit per parameter range].
    pub mu: Vec<f64>,
    /// Mean absolute elementary effect [metric unit per parameter range].
    pub mu_star: Vec<f64>,
    /// Standard deviation of the elementary effects [metric unit per parameter range].
    pub sigma: Vec<f64>,
    /// Trajectories used.
    pub n_used: usize,
    /// Trajectories dropped because a run failed or was missing.
    pub n_dropped: usize,
    /// Why values are NaN, or other caveats; `None` when all is well.
    pub note: Option<String>,
}

/// Statistics over `trajectories`: each item is a trajectory's steps (from
/// [`trajectory_steps`]) and its `steps.len() + 1` outputs, or `None` for a trajectory
/// that is incomplete in the design (counted as dropped).
pub fn morris_statistics(
    dims: usize,
    trajectories: &[Option<(&[MorrisStep], &[f64])>],
) -> MorrisEstimate {
    let mut effects = vec![Vec::new(); dims];
    let mut n_used = 0;
    for (steps, y) in trajectories.iter().flatten() {
        if y.len() != steps.len() + 1 || y.iter().any(|v| !v.is_finite()) {
            continue;
        }
        n_used += 1;
        for (s, step) in steps.iter().enumerate() {
            effects[step.parameter].push((y[s + 1] - y[s]) / step.delta);
        }
    }
    let n_dropped = trajectories.len() - n_used;
    let abs_mean = |e: &Vec<f64>| e.iter().map(|x| x.abs()).sum::<f64>() / e.len() as f64;
    let note = if n_used == 0 {
        Some(format!("no usable trajectory: all {n_dropped} had failed or missing runs"))
    } else if n_used < 2 {
        Some("only one usable trajectory: sigma undefined".to_string())
    } else {
        (n_dropped > 0).then(|| {
            format!("{n_dropped} of {} trajectories dropped for failed runs", trajectories.len())
        })
    };
    MorrisEstimate {
        mu: effects.iter().map(|e| mean(e)).collect(),
        mu_star: effects.iter().map(abs_mean).collect(),
        sigma: effects.iter().map(|e| sample_std(e)).collect(),
        n_used,
        n_dropped,
        note,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_model_effects_are_its_slopes_per_range() {
        // y = 3·u0 − 2·u1 in unit coordinates.
        let pts: [&[f64]; 3] = [&[0.0, 2.0 / 3.0], &[2.0 / 3.0, 2.0 / 3.0], &[2.0 / 3.0, 0.0]];
        let steps = trajectory_steps(0, &pts).unwrap();
        let y: Vec<f64> = pts.iter().map(|u| 3.0 * u[0] - 2.0 * u[1]).collect();
        let est = morris_statistics(2, &[Some((&steps, &y)), Some((&steps, &y))]);
        assert!((est.mu[0] - 3.0).abs() < 1e-12 && (est.mu[1] + 2.0).abs() < 1e-12);
        assert!((est.mu_star[1] - 2.0).abs() < 1e-12);
        assert!(est.sigma[0].abs() < 1e-12);
        assert_eq!((est.n_used, est.n_dropped), (2, 0));
    }

    #[test]
    fn failed_trajectory_is_dropped_and_counted() {
        let pts: [&[f64]; 2] = [&[0.0], &[1.0]];
        let steps = trajectory_steps(0, &pts).unwrap();
        let good = [0.0, 1.0];
        let bad = [0.0, f64::NAN];
        let est = morris_statistics(1, &[Some((&steps, &good)), Some((&steps, &bad)), None]);
        assert_eq!((est.n_used, est.n_dropped), (1, 2));
        assert_eq!(est.mu_star[0], 1.0);
        assert!(est.sigma[0].is_nan());
    }

    #[test]
    fn rejects_steps_that_move_two_coordinates() {
        let pts: [&[f64]; 2] = [&[0.0, 0.0], &[1.0, 1.0]];
        assert!(matches!(trajectory_steps(4, &pts), Err(SensitivityError::NotOneAtATime { .. })));
    }
}
