//! Typed errors of the sensitivity module: bad designs, bad inputs, inconsistent tables.

use thiserror::Error;

/// What went wrong while building a design or estimating indices.
///
/// A failed *run* (a NaN metric) is not an error: it is dropped and counted in the result
/// rows. These errors mean the request itself cannot be carried out.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SensitivityError {
    /// The Sobol' sequence has direction numbers for `max` dimensions only.
    #[error(
        "the Sobol' sequence supports at most {max} dimensions, {dims} requested \
         (a Saltelli design needs 2 per parameter)"
    )]
    TooManyDimensions {
        /// Dimensions requested.
        dims: usize,
        /// Dimensions available.
        max: usize,
    },
    /// A design needs at least one parameter.
    #[error("a sensitivity design needs at least one parameter")]
    NoParameters,
    /// A sample or trajectory count of zero, or too large for the sequence.
    #[error("{what} must be between {min} and {max}, got {got}")]
    BadCount {
        /// Which count (`base samples`, `trajectories`, `bootstrap resamples`).
        what: &'static str,
        /// Value given.
        got: usize,
        /// Smallest accepted value.
        min: usize,
        /// Largest accepted value.
        max: usize,
    },
    /// Morris levels must be an even number ≥ 2 so the step Δ = p/(2(p−1)) lies on the grid.
    #[error("Morris levels must be an even number >= 2, got {levels}")]
    BadLevels {
        /// Levels given.
        levels: usize,
    },
    /// A parameter range that cannot be sampled.
    #[error("parameter `{name}`: bounds [{lo}, {hi}] {reason}")]
    BadRange {
        /// Parameter name.
        name: String,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
        /// Why the bounds are rejected.
        reason: &'static str,
    },
    /// The confidence level of the bootstrap intervals must lie in (0, 1).
    #[error("confidence level must lie strictly between 0 and 1, got {0}")]
    BadConfidence(f64),
    /// A point whose unit coordinates do not match the number of parameters.
    #[error("design point {index} has {got} coordinates, expected {expected} (one per parameter)")]
    PointWidth {
        /// Index of the point in the given list.
        index: usize,
        /// Coordinates found.
        got: usize,
        /// Parameters named.
        expected: usize,
    },
    /// A metric column whose length differs from the number of design points.
    #[error("metric `{metric}` has {got} values for {expected} design points")]
    MetricLength {
        /// Metric name.
        metric: String,
        /// Values given.
        got: usize,
        /// Points given.
        expected: usize,
    },
    /// Points of both methods in one analysis.
    #[error("the design mixes Sobol' and Morris points")]
    MixedMethods,
    /// An empty design.
    #[error("the design has no points")]
    EmptyDesign,
    /// Two points with the same tag.
    #[error("design point {index} repeats the tag {tag}")]
    DuplicateTag {
        /// Index of the second occurrence.
        index: usize,
        /// The repeated tag, as text.
        tag: String,
    },
    /// A tag that cannot belong to a design over this many parameters.
    #[error("design point {index}: tag {tag} does not fit a design over {dims} parameters")]
    TagOutOfRange {
        /// Index of the point.
        index: usize,
        /// The tag, as text.
        tag: String,
        /// Parameters named.
        dims: usize,
    },
    /// Consecutive Morris points that do not differ in exactly one coordinate.
    #[error(
        "Morris trajectory {trajectory}: step {step} changes {changed} coordinates, expected exactly 1"
    )]
    NotOneAtATime {
        /// Trajectory index.
        trajectory: usize,
        /// Step index (1-based: the move from step−1 to step).
        step: usize,
        /// Coordinates that differ.
        changed: usize,
    },
}

/// Result alias for this module.
pub type Result<T, E = SensitivityError> = std::result::Result<T, E>;
