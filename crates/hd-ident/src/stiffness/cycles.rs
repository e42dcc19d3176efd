//! Cycles of a deflection record and the loop energy per cycle: the reversals of θ (with a
//! threshold above its noise), cycles between upward crossings of the middle of θ's range,
//! and blocks of consecutive cycles of about the same amplitude. A rate-independent test
//! (amplitude steps at slow rates) falls into one block per amplitude; an irregular record
//! into many short ones.

use serde::Serialize;

/// Consecutive cycles whose amplitudes differ by less than this share join one block.
pub const BLOCK_TOLERANCE: f64 = 0.1;
/// Cycles smaller than this share of the largest amplitude are left out.
pub const SMALLEST_CYCLE: f64 = 0.05;
/// At most this many blocks are reported (the largest-amplitude ones are kept).
pub const MAX_BLOCKS: usize = 40;

/// One block of cycles of about the same amplitude.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoopBlock {
    /// Mean half peak-to-peak deflection of the block's cycles [rad].
    pub amplitude: f64,
    /// Whole cycles in the block.
    pub cycles: usize,
    /// First and last row of the block (0-based, into the record).
    pub rows: [usize; 2],
    /// Energy per cycle of the fitted law, ∮ Tb dθ along the measured θ [J].
    pub model_energy_per_cycle: f64,
    /// Energy per cycle of the measured torque [J] (noise averages out over a cycle).
    pub measured_energy_per_cycle: f64,
}

/// The smallest move of θ that counts as a reversal: max(1e-3 of the span, 10 × the noise
/// of θ estimated from the median of its second differences) [rad].
pub fn threshold(theta: &[f64]) -> f64 {
    let (lo, hi) =
        theta.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
    if theta.len() < 3 {
        return 1e-3 * (hi - lo);
    }
    let mut d2: Vec<f64> = theta.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).abs()).collect();
    d2.sort_by(f64::total_cmp);
    let noise = d2[d2.len() / 2] / (6f64.sqrt() * 0.6745);
    (1e-3 * (hi - lo)).max(10.0 * noise)
}

/// Rows where θ reverses, with a threshold of max(1e-3 of the span, 10 × the noise of θ
/// estimated from its second differences): alternating maxima and minima.
pub fn reversals(theta: &[f64]) -> Vec<usize> {
    let n = theta.len();
    if n < 3 {
        return Vec::new();
    }
    let eps = threshold(theta);
    let mut out = Vec::new();
    // Direction 0 until the first move beyond eps from the start.
    let (mut dir, mut ext) = (0i8, 0usize);
    for k in 1..n {
        match dir {
            0 => {
                if (theta[k] - theta[0]).abs() > eps {
                    dir = if theta[k] > theta[0] { 1 } else { -1 };
                    ext = k;
                }
            }
            1 => {
                if theta[k] > theta[ext] {
                    ext = k;
                } else if theta[ext] - theta[k] > eps {
                    out.push(ext);
                    dir = -1;
                    ext = k;
                }
            }
            _ => {
                if theta[k] < theta[ext] {
                    ext = k;
                } else if theta[k] - theta[ext] > eps {
                    out.push(ext);
                    dir = 1;
                    ext = k;
                }
            }
        }
    }
    out
}

/// A cycle: first row, last row, amplitude [rad].
type Cycle = (usize, usize, f64);

fn loop_integral(theta: &[f64], torque: &[f64], a: usize, b: usize) -> f64 {
    (a..b).map(|k| 0.5 * (torque[k] + torque[k + 1]) * (theta[k + 1] - theta[k])).sum()
}

/// Rows where θ crosses the middle of its range upwards, each counted only after θ has
/// been below the middle by the reversal threshold: the starts of whole cycles.
pub fn upward_crossings(theta: &[f64]) -> Vec<usize> {
    let (lo, hi) =
        theta.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
    let mid = 0.5 * (lo + hi);
    let eps = threshold(theta);
    let mut armed = theta.first().is_some_and(|&v| v < mid);
    let mut out = Vec::new();
    // A record that starts at the middle and rises starts a cycle at its first row.
    if (theta[0] - mid).abs() <= eps
        && theta.iter().find(|v| (*v - theta[0]).abs() > eps).is_some_and(|&v| v > theta[0])
    {
        out.push(0);
    }
    for k in 1..theta.len() {
        if theta[k] < mid - eps {
            armed = true;
        }
        if armed && theta[k - 1] < mid && theta[k] >= mid {
            out.push(k);
            armed = false;
        }
    }
    out
}

/// The loop energy per cycle of `model` and `measured` torque along `theta`, per block of
/// consecutive cycles of similar amplitude. A cycle runs from one upward crossing of the
/// middle of θ's range to the next, so a test that changes amplitude only at the middle
/// (as sinusoidal blocks starting at zero do) has one block per amplitude. A record
/// whose θ does not swing through the middle of its range has no cycles.
pub fn loop_energies(theta: &[f64], measured: &[f64], model: &[f64]) -> Vec<LoopBlock> {
    let ups = upward_crossings(theta);
    let cycles: Vec<Cycle> = ups
        .windows(2)
        .map(|w| {
            let (lo, hi) = theta[w[0]..=w[1]]
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
            (w[0], w[1], 0.5 * (hi - lo))
        })
        .collect();
    let largest = cycles.iter().map(|c| c.2).fold(0.0, f64::max);
    let mut blocks: Vec<(Vec<Cycle>, f64)> = Vec::new();
    for c in cycles.into_iter().filter(|c| c.2 >= SMALLEST_CYCLE * largest) {
        match blocks.last_mut() {
            Some((members, first))
                if (c.2 / *first - 1.0).abs() < BLOCK_TOLERANCE
                    && members.last().is_some_and(|m| m.1 == c.0) =>
            {
                members.push(c)
            }
            _ => blocks.push((vec![c], c.2)),
        }
    }
    let mut out: Vec<LoopBlock> = blocks
        .into_iter()
        .map(|(members, _)| {
            let m = members.len() as f64;
            let (a, b) = (members[0].0, members[members.len() - 1].1);
            LoopBlock {
                amplitude: members.iter().map(|c| c.2).sum::<f64>() / m,
                cycles: members.len(),
                rows: [a, b],
                model_energy_per_cycle: loop_integral(theta, model, a, b) / m,
                measured_energy_per_cycle: loop_integral(theta, measured, a, b) / m,
            }
        })
        .collect();
    if out.len() > MAX_BLOCKS {
        out.sort_by(|x, y| y.amplitude.total_cmp(&x.amplitude));
        out.truncate(MAX_BLOCKS);
        out.sort_by_key(|b| b.rows[0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn finds_blocks_and_the_energy_of_a_known_loop() {
        // Two blocks: 3 cycles at 1e-3 rad, then 3 at 4e-4 rad; torque k·θ + d·θ̇-like
        // loop T = 1e4·θ + 5·cos(phase): ∮ T dθ = 5·π·C per cycle.
        let mut theta = Vec::new();
        let mut torque = Vec::new();
        for (c, cycles) in [(1e-3, 3), (4e-4, 3)] {
            for k in 0..cycles * 1000 {
                let ph = TAU * k as f64 / 1000.0;
                theta.push(c * ph.sin());
                torque.push(1e4 * c * ph.sin() + 5.0 * ph.cos());
            }
        }
        theta.push(0.0);
        torque.push(5.0);
        let blocks = loop_energies(&theta, &torque, &torque);
        assert_eq!(blocks.len(), 2, "{blocks:?}");
        assert_eq!((blocks[0].cycles, blocks[1].cycles), (3, 3));
        for (b, c) in [(&blocks[0], 1e-3), (&blocks[1], 4e-4)] {
            assert!((b.amplitude / c - 1.0).abs() < 1e-4, "{b:?}");
            let exact = 5.0 * std::f64::consts::PI * c;
            // Measured relative error ≈ 3e-6 (trapezoid over 1000 samples per cycle).
            assert!((b.model_energy_per_cycle / exact - 1.0).abs() < 3e-5, "{b:?}");
        }
    }
}
