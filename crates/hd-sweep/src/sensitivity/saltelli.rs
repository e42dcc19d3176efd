//! The Saltelli design for Sobol' indices: matrices A, B and A_B^(i), i = 0 … d−1.
//!
//! Following Saltelli et al. (2010), A and B are the first and last `d` coordinates of a
//! `2d`-dimensional Sobol' sequence, and A_B^(i) is A with column `i` replaced by B's.
//! With `N` base samples the design has `N·(d + 2)` points.
//!
//! **Row order.** Grouped by base index `j = 0 … N−1`; within a group:
//! `A_j, A_B^(0)_j, …, A_B^(d−1)_j, B_j`, i.e. row `j·(d + 2) + Block::position(d)`. This is
//! the order SALib uses for first- and total-order designs.
//!
//! **Which sequence points.** With a shift seed the sequence gets a random digital shift and
//! points 0 … N−1 are used. Without one the plain sequence is used from point 1 (point 0 is
//! the origin, a corner of the cube). Powers of two for `N` keep the net balance properties.

use super::design::{Block, Design, DesignPoint, PointTag, SensitivityMethod, check_count};
use super::error::{Result, SensitivityError};
use super::sobol_sequence::SobolSequence;

/// Largest number of base samples accepted (2^30).
pub const MAX_BASE_SAMPLES: usize = 1 << 30;

/// Build a Saltelli design over `dims` parameters with `n_base` base samples.
///
/// `shift_seed`: `Some(seed)` applies a seeded random digital shift to the Sobol' sequence;
/// `None` uses the standard sequence (skipping its first point). Fails when `2·dims`
/// exceeds [`SobolSequence::MAX_DIMS`] or `n_base` is 0 or above [`MAX_BASE_SAMPLES`].
pub fn saltelli_design(dims: usize, n_base: usize, shift_seed: Option<u64>) -> Result<Design> {
    if dims == 0 {
        return Err(SensitivityError::NoParameters);
    }
    if 2 * dims > SobolSequence::MAX_DIMS {
        return Err(SensitivityError::TooManyDimensions {
            dims: 2 * dims,
            max: SobolSequence::MAX_DIMS,
        });
    }
    check_count("base samples", n_base, 1, MAX_BASE_SAMPLES)?;
    let mut seq = SobolSequence::new(2 * dims)?;
    let first = match shift_seed {
        Some(seed) => {
            seq = seq.with_digital_shift(seed);
            0
        }
        None => 1,
    };
    let mut points = Vec::with_capacity(n_base * (dims + 2));
    let mut buf = vec![0.0; 2 * dims];
    for j in 0..n_base {
        // n_base ≤ 2^30, so the index fits in u32.
        seq.fill_point((first + j) as u32, &mut buf);
        let (a, b) = buf.split_at(dims);
        for pos in 0..dims + 2 {
            let block = Block::from_position(pos, dims).expect("pos ≤ dims + 1");
            let unit = match block {
                Block::A => a.to_vec(),
                Block::B => b.to_vec(),
                Block::AB(i) => {
                    let mut row = a.to_vec();
                    row[i] = b[i];
                    row
                }
            };
            points.push(DesignPoint { tag: PointTag::Sobol { base: j, block }, unit });
        }
    }
    Ok(Design { method: SensitivityMethod::Sobol, dims, points })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_order_and_columns() {
        let d = 3;
        let design = saltelli_design(d, 4, Some(1)).unwrap();
        assert_eq!(design.len(), 4 * (d + 2));
        for j in 0..4 {
            let row = |b: Block| &design.points[j * (d + 2) + b.position(d)];
            let (a, b) = (row(Block::A), row(Block::B));
            assert_eq!(a.tag, PointTag::Sobol { base: j, block: Block::A });
            for i in 0..d {
                let ab = row(Block::AB(i));
                assert_eq!(ab.tag, PointTag::Sobol { base: j, block: Block::AB(i) });
                for k in 0..d {
                    let want = if k == i { b.unit[k] } else { a.unit[k] };
                    assert_eq!(ab.unit[k], want);
                }
            }
        }
    }

    #[test]
    fn unshifted_design_skips_the_origin() {
        let design = saltelli_design(2, 2, None).unwrap();
        assert_eq!(design.points[0].unit, [0.5, 0.5]);
        assert_eq!(design.points[3].unit, [0.5, 0.5]);
    }
}
