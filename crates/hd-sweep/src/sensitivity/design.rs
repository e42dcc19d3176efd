//! A sensitivity design: points in the unit hypercube, each tagged with its place in the
//! Saltelli or Morris structure.
//!
//! The tags, not the order of the points, carry the structure: a study may run and store
//! the points in any order (parallel runs, resumed sweeps) and the analysis regroups them.

use super::error::{Result, SensitivityError};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// The two global methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SensitivityMethod {
    /// Variance-based indices from a Saltelli design.
    Sobol,
    /// Elementary-effects screening from Morris trajectories.
    Morris,
}

impl SensitivityMethod {
    /// Lower-case name, as used in study files and result tables.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Sobol => "sobol",
            Self::Morris => "morris",
        }
    }
}

impl fmt::Display for SensitivityMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Which matrix of the Saltelli design a point comes from.
///
/// `A` and `B` are two independent samples; `AB(i)` is `A` with column `i` (0-based
/// parameter index) taken from `B`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Block {
    /// Row of matrix A.
    A,
    /// Row of matrix A_B^(i): A with column `i` from B.
    AB(usize),
    /// Row of matrix B.
    B,
}

impl Block {
    /// Position within a base row's group of `dims + 2` points: A → 0, AB(i) → i + 1,
    /// B → dims + 1. This is also the row order of [`super::saltelli_design`].
    pub fn position(self, dims: usize) -> usize {
        match self {
            Self::A => 0,
            Self::AB(i) => i + 1,
            Self::B => dims + 1,
        }
    }

    /// Inverse of [`Self::position`]; `None` when `pos > dims + 1`.
    pub fn from_position(pos: usize, dims: usize) -> Option<Self> {
        match pos {
            0 => Some(Self::A),
            p if p <= dims => Some(Self::AB(p - 1)),
            p if p == dims + 1 => Some(Self::B),
            _ => None,
        }
    }
}

impl fmt::Display for Block {
    /// `A`, `B`, or `AB<i>` with the 0-based parameter index, e.g. `AB0`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::A => f.write_str("A"),
            Self::B => f.write_str("B"),
            Self::AB(i) => write!(f, "AB{i}"),
        }
    }
}

impl FromStr for Block {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "A" => Ok(Self::A),
            "B" => Ok(Self::B),
            _ => s
                .strip_prefix("AB")
                .and_then(|i| i.parse().ok())
                .map(Self::AB)
                .ok_or_else(|| format!("`{s}` is not a Saltelli block (A, B or AB<i>)")),
        }
    }
}

/// Where a point sits in its design.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "lowercase")]
pub enum PointTag {
    /// Saltelli point: base-sample index `base` (0-based) and matrix `block`.
    Sobol {
        /// Base-sample index j (0-based); the `dims + 2` points with the same `base` form
        /// one base row.
        base: usize,
        /// Matrix the point comes from.
        block: Block,
    },
    /// Morris point: trajectory index and step within it.
    Morris {
        /// Trajectory index (0-based).
        trajectory: usize,
        /// Step 0 is the start; step k ≥ 1 differs from step k−1 in one coordinate.
        step: usize,
    },
}

impl PointTag {
    /// The method this tag belongs to.
    pub fn method(&self) -> SensitivityMethod {
        match self {
            Self::Sobol { .. } => SensitivityMethod::Sobol,
            Self::Morris { .. } => SensitivityMethod::Morris,
        }
    }

    /// Flat form for table columns: `(method, group, slot)` where group is the base index
    /// or trajectory and slot is [`Block::position`] or the step.
    pub fn to_parts(&self, dims: usize) -> (SensitivityMethod, usize, usize) {
        match *self {
            Self::Sobol { base, block } => (SensitivityMethod::Sobol, base, block.position(dims)),
            Self::Morris { trajectory, step } => (SensitivityMethod::Morris, trajectory, step),
        }
    }

    /// Inverse of [`Self::to_parts`]; `None` when the slot cannot exist with `dims`
    /// parameters.
    pub fn from_parts(
        method: SensitivityMethod,
        group: usize,
        slot: usize,
        dims: usize,
    ) -> Option<Self> {
        match method {
            SensitivityMethod::Sobol => {
                Block::from_position(slot, dims).map(|block| Self::Sobol { base: group, block })
            }
            SensitivityMethod::Morris => {
                (slot <= dims).then_some(Self::Morris { trajectory: group, step: slot })
            }
        }
    }
}

impl fmt::Display for PointTag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Sobol { base, block } => write!(f, "sobol base {base} block {block}"),
            Self::Morris { trajectory, step } => {
                write!(f, "morris trajectory {trajectory} step {step}")
            }
        }
    }
}

/// One point of a design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DesignPoint {
    /// Its place in the design.
    pub tag: PointTag,
    /// Coordinates in `[0, 1]^dims`, one per parameter; map with
    /// [`super::ParamRange::from_unit`].
    pub unit: Vec<f64>,
}

/// A complete design over `dims` parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Design {
    /// Method the design is built for.
    pub method: SensitivityMethod,
    /// Number of parameters.
    pub dims: usize,
    /// The points, in the generator's documented order.
    pub points: Vec<DesignPoint>,
}

impl Design {
    /// Number of points (model runs).
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when the design has no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }
}

/// Check a count against `[min, max]`.
pub(crate) fn check_count(what: &'static str, got: usize, min: usize, max: usize) -> Result<()> {
    if (min..=max).contains(&got) {
        Ok(())
    } else {
        Err(SensitivityError::BadCount { what, got, min, max })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_labels_and_positions_round_trip() {
        for b in [Block::A, Block::AB(0), Block::AB(2), Block::B] {
            assert_eq!(b.to_string().parse::<Block>(), Ok(b));
            assert_eq!(Block::from_position(b.position(3), 3), Some(b));
        }
        assert_eq!(Block::from_position(5, 3), None);
    }

    #[test]
    fn tag_parts_round_trip() {
        let tags = [
            PointTag::Sobol { base: 7, block: Block::AB(1) },
            PointTag::Morris { trajectory: 4, step: 3 },
        ];
        for t in tags {
            let (m, g, s) = t.to_parts(3);
            assert_eq!(PointTag::from_parts(m, g, s, 3), Some(t));
        }
    }
}
