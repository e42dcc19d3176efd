//! Where an encoder creeps, its quantisation error is not noise. While the shaft moves
//! several counts per sample the rounding error is as good as independent from sample to
//! sample; while it moves less than a count, the error is a staircase fixed by the true
//! angle, and a parameter whose effect lies there (the bristle's pre-sliding deflection at a
//! reversal is a fraction of a count) can be fitted to the staircase. Its linearised
//! standard error then counts staircase steps as independent information. A parameter that
//! draws most of its information ([`CREEPING_SHARE`]) from such samples is reported as not
//! determined.

use super::fit::{CompliantSpec, Signal, blocks};
use super::record::VoltageRecord;
use nalgebra::DMatrix;
use std::ops::Range;

/// Share of a parameter's information from creeping encoder samples above which it is not
/// determined [–].
pub const CREEPING_SHARE: f64 = 0.5;

/// Per sample of `x`: whether the encoder moves less than 1.5 counts (`count` [rad]) to the
/// next sample (or from the previous one, at the end).
pub fn creeping(x: &[f64], count: f64) -> Vec<bool> {
    (0..x.len())
        .map(|i| {
            let j = if i + 1 < x.len() { i + 1 } else { i.saturating_sub(1) };
            (x[j] - x[i]).abs() < 1.5 * count
        })
        .collect()
}

/// The count of an encoder whose noise level is `sigma` [rad]: the rounding error of a
/// moving encoder is uniform over one count, so its standard deviation is count/√12.
pub fn count_of(sigma: f64) -> f64 {
    sigma * 12f64.sqrt()
}

/// Per column of `jac`: the share of its information Σ J² that comes from the rows the
/// masks mark (`masks` pairs row ranges with a mask over them).
pub fn creeping_share(jac: &DMatrix<f64>, masks: &[(Range<usize>, Vec<bool>)]) -> Vec<f64> {
    (0..jac.ncols())
        .map(|c| {
            let col = jac.column(c);
            let total: f64 = col.iter().map(|v| v * v).sum();
            let creep: f64 = masks
                .iter()
                .flat_map(|(range, mask)| range.clone().zip(mask).filter(|(_, m)| **m))
                .map(|(i, _)| col[i] * col[i])
                .sum();
            if total > 0.0 { creep / total } else { 0.0 }
        })
        .collect()
}

/// The creeping masks of `records` as `spec` compares them: for every residual block of an
/// output `keep` accepts, its rows and whether each sample creeps, with the output's count
/// taken from its noise level ([`count_of`]).
pub fn masks(
    spec: &CompliantSpec,
    records: &[VoltageRecord],
    keep: impl Fn(Signal) -> bool,
) -> Vec<(Range<usize>, Vec<bool>)> {
    blocks(spec, records)
        .into_iter()
        .filter(|(_, o, _)| keep(*o))
        .filter_map(|(k, o, range)| {
            let sigma = spec.outputs.iter().find(|(s, _)| *s == o)?.1[k];
            Some((range, creeping(o.measured(&records[k])?, count_of(sigma))))
        })
        .collect()
}

/// Zero the rows of `jac` the masks mark: what the information keeps once the creeping
/// samples' staircase is not counted as independent noise.
pub fn drop_creeping(jac: &mut DMatrix<f64>, masks: &[(Range<usize>, Vec<bool>)]) {
    for (range, mask) in masks {
        for (i, _) in range.clone().zip(mask).filter(|(_, m)| **m) {
            jac.row_mut(i).fill(0.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp of 0.3 counts per sample creeps; of 3 counts per sample it does not. A column
    /// whose weight sits on the creeping half gets its share from there.
    #[test]
    fn creeping_samples_and_their_share() {
        let q = 0.01;
        let slow: Vec<f64> = (0..100).map(|k| (0.3 * k as f64).round() * q).collect();
        let fast: Vec<f64> = (0..100).map(|k| (3.0 * k as f64).round() * q).collect();
        assert!(creeping(&slow, q).iter().all(|&c| c));
        assert!(creeping(&fast, q).iter().all(|&c| !c));
        assert!((count_of(q / 12f64.sqrt()) - q).abs() < 1e-15);
        let mut jac = DMatrix::zeros(200, 2);
        for i in 0..200 {
            jac[(i, 0)] = if i < 100 { 3.0 } else { 1.0 };
            jac[(i, 1)] = 1.0;
        }
        let masks = vec![(0..100, creeping(&slow, q)), (100..200, creeping(&fast, q))];
        let share = creeping_share(&jac, &masks);
        assert!((share[0] - 0.9).abs() < 1e-12 && (share[1] - 0.5).abs() < 1e-12, "{share:?}");
    }
}
