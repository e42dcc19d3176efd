//! Morris trajectories (one-at-a-time designs) on a `p`-level grid in the unit hypercube.
//!
//! Morris (1991), in the form of Campolongo, Cariboni & Saltelli (2007) without trajectory
//! optimisation. The grid is `{0, 1/(p−1), …, 1}` per coordinate and the step is
//! `Δ = p / (2(p−1))` (half the grid's levels), so `p` must be even. Each trajectory:
//! 1. draws a start level for every coordinate uniformly among all `p` levels, restricted
//!    so that moving by Δ stays on the grid (levels below Δ move up, the others down);
//! 2. draws a random order of the coordinates;
//! 3. moves the coordinates one at a time in that order, by +Δ or −Δ.
//!
//! This gives `d + 1` points per trajectory and `r·(d + 1)` in all.
//!
//! **Row order.** Trajectory by trajectory, steps `0 … d` within each: row
//! `t·(d + 1) + step`.

use super::design::{Design, DesignPoint, PointTag, SensitivityMethod, check_count};
use super::error::{Result, SensitivityError};
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Largest number of trajectories accepted.
pub const MAX_TRAJECTORIES: usize = 1 << 24;

/// The Morris step in unit coordinates for `levels` grid levels: `p / (2(p−1))`.
pub fn morris_delta(levels: usize) -> f64 {
    levels as f64 / (2.0 * (levels as f64 - 1.0))
}

/// Build `trajectories` Morris trajectories over `dims` parameters on a `levels`-level grid,
/// drawn from a ChaCha8 generator seeded with `seed`.
///
/// `levels` must be even and ≥ 2 (4 is the common choice).
pub fn morris_design(dims: usize, trajectories: usize, levels: usize, seed: u64) -> Result<Design> {
    if dims == 0 {
        return Err(SensitivityError::NoParameters);
    }
    if levels < 2 || !levels.is_multiple_of(2) {
        return Err(SensitivityError::BadLevels { levels });
    }
    check_count("trajectories", trajectories, 1, MAX_TRAJECTORIES)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let half = levels / 2; // Δ spans `half` grid intervals
    let grid = |k: usize| k as f64 / (levels - 1) as f64;
    let mut points = Vec::with_capacity(trajectories * (dims + 1));
    let mut order: Vec<usize> = (0..dims).collect();
    for t in 0..trajectories {
        // Start level index per coordinate, uniform over 0..levels.
        let mut level: Vec<usize> = (0..dims).map(|_| rng.random_range(0..levels)).collect();
        order.shuffle(&mut rng);
        let mut unit: Vec<f64> = level.iter().map(|&k| grid(k)).collect();
        points.push(DesignPoint {
            tag: PointTag::Morris { trajectory: t, step: 0 },
            unit: unit.clone(),
        });
        for (s, &i) in order.iter().enumerate() {
            level[i] = if level[i] < half { level[i] + half } else { level[i] - half };
            unit[i] = grid(level[i]);
            points.push(DesignPoint {
                tag: PointTag::Morris { trajectory: t, step: s + 1 },
                unit: unit.clone(),
            });
        }
    }
    Ok(Design { method: SensitivityMethod::Morris, dims, points })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_move_one_coordinate_by_delta() {
        let (d, p) = (5, 4);
        let design = morris_design(d, 20, p, 3).unwrap();
        assert_eq!(design.len(), 20 * (d + 1));
        let delta = morris_delta(p);
        for t in 0..20 {
            let traj = &design.points[t * (d + 1)..(t + 1) * (d + 1)];
            let mut moved = vec![false; d];
            for w in traj.windows(2) {
                let diffs: Vec<usize> = (0..d).filter(|&k| w[0].unit[k] != w[1].unit[k]).collect();
                assert_eq!(diffs.len(), 1);
                let k = diffs[0];
                assert!(((w[1].unit[k] - w[0].unit[k]).abs() - delta).abs() < 1e-12);
                assert!(!moved[k], "each coordinate moves once");
                moved[k] = true;
            }
            assert!(traj.iter().flat_map(|p| &p.unit).all(|&u| (0.0..=1.0).contains(&u)));
        }
    }

    #[test]
    fn rejects_odd_levels() {
        assert!(matches!(morris_design(2, 4, 3, 0), Err(SensitivityError::BadLevels { .. })));
    }
}
