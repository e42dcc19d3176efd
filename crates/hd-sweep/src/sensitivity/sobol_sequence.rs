//! The Sobol' low-discrepancy sequence in the unit hypercube, with an optional seeded
//! random digital shift.
//!
//! Construction (Bratley & Fox 1988, Algorithm 659; Joe & Kuo 2003): each dimension `j` has
//! 32 direction integers `V_1 … V_32`; the first `s` are `m_k · 2^(32−k)` from the published
//! initial numbers, the rest follow from the primitive polynomial's recurrence
//! `V_k = a_1 V_(k−1) ⊕ … ⊕ a_(s−1) V_(k−s+1) ⊕ V_(k−s) ⊕ (V_(k−s) >> s)`.
//! Point `n` (0-based) XORs the `V_k` selected by the bits of its Gray code `g = n ⊕ (n >> 1)`,
//! which is the Antonov–Saleev order used by SciPy's `qmc.Sobol(scramble=False)` and SALib;
//! point 0 is the origin, point 1 is (½, …, ½).
//!
//! A *random digital shift* XORs every coordinate's 32-bit integer with a fixed random mask
//! per dimension. It keeps the net structure (every elementary box still holds its share
//! of points) while moving the sequence off the corner at the origin; different seeds give
//! independent randomisations of the same quality.

use super::direction_numbers::{JOE_KUO_D6, MAX_DIMS};
use super::error::{Result, SensitivityError};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Bits per coordinate; the sequence has 2^32 distinct points.
const BITS: usize = 32;

/// Scale from a 32-bit integer to [0, 1).
const TO_UNIT: f64 = 1.0 / 4_294_967_296.0;

/// A generator of Sobol' points in `[0, 1)^dims`, addressable by index.
#[derive(Clone, Debug)]
pub struct SobolSequence {
    /// Direction integers, one array per dimension.
    directions: Vec<[u32; BITS]>,
    /// Digital-shift mask per dimension (all zero when unshifted).
    shift: Vec<u32>,
}

impl SobolSequence {
    /// The standard (unshifted) sequence in `dims` dimensions, 1 ≤ `dims` ≤ [`Self::MAX_DIMS`].
    pub fn new(dims: usize) -> Result<Self> {
        if dims == 0 {
            return Err(SensitivityError::NoParameters);
        }
        if dims > MAX_DIMS {
            return Err(SensitivityError::TooManyDimensions { dims, max: MAX_DIMS });
        }
        Ok(Self { directions: (0..dims).map(directions).collect(), shift: vec![0; dims] })
    }

    /// Apply a random digital shift drawn from `seed` (ChaCha8). Replaces any earlier shift.
    pub fn with_digital_shift(mut self, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        for s in &mut self.shift {
            *s = rng.random::<u32>();
        }
        self
    }

    /// Largest number of dimensions available (from the embedded direction numbers).
    pub const MAX_DIMS: usize = MAX_DIMS;

    /// Number of dimensions.
    pub fn dims(&self) -> usize {
        self.directions.len()
    }

    /// Write point `index` (0-based) into `out`, which must have [`Self::dims`] entries.
    pub fn fill_point(&self, index: u32, out: &mut [f64]) {
        assert_eq!(out.len(), self.dims(), "output slice must have one entry per dimension");
        let gray = index ^ (index >> 1);
        for ((o, dirs), shift) in out.iter_mut().zip(&self.directions).zip(&self.shift) {
            let mut x = *shift;
            let mut g = gray;
            let mut k = 0;
            while g != 0 {
                if g & 1 == 1 {
                    x ^= dirs[k];
                }
                g >>= 1;
                k += 1;
            }
            *o = f64::from(x) * TO_UNIT;
        }
    }

    /// Point `index` (0-based) as a new vector.
    pub fn point(&self, index: u32) -> Vec<f64> {
        let mut out = vec![0.0; self.dims()];
        self.fill_point(index, &mut out);
        out
    }
}

/// Direction integers of dimension `j` (0-based).
fn directions(j: usize) -> [u32; BITS] {
    let mut v = [0u32; BITS];
    if j == 0 {
        for (k, vk) in v.iter_mut().enumerate() {
            *vk = 1 << (BITS - 1 - k);
        }
        return v;
    }
    let (a, m) = JOE_KUO_D6[j - 1];
    let s = m.len();
    for k in 0..s.min(BITS) {
        v[k] = m[k] << (BITS - 1 - k);
    }
    for k in s..BITS {
        let mut x = v[k - s] ^ (v[k - s] >> s);
        for i in 1..s {
            if (a >> (s - 1 - i)) & 1 == 1 {
                x ^= v[k - i];
            }
        }
        v[k] = x;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_dimension_is_van_der_corput_in_gray_order() {
        let s = SobolSequence::new(1).unwrap();
        let xs: Vec<f64> = (0..8).map(|n| s.point(n)[0]).collect();
        assert_eq!(xs, [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125]);
    }

    #[test]
    fn shift_keeps_one_point_per_dyadic_interval() {
        let s = SobolSequence::new(4).unwrap().with_digital_shift(11);
        for d in 0..4 {
            let mut seen = [false; 16];
            for n in 0..16 {
                seen[(s.point(n)[d] * 16.0) as usize] = true;
            }
            assert!(seen.iter().all(|&b| b), "dimension {d}");
        }
    }

    #[test]
    fn rejects_too_many_dimensions() {
        assert!(SobolSequence::new(MAX_DIMS).is_ok());
        assert!(matches!(
            SobolSequence::new(MAX_DIMS + 1),
            Err(SensitivityError::TooManyDimensions { .. })
        ));
    }
}
