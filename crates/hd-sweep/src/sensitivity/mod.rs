//! Global sensitivity analysis: Sobol' indices and Morris screening over a unit-cube design.
//!
//! The pieces, in the order a study uses them:
//! - [`ParamRange`]: a parameter's bounds and scale; maps unit coordinates to values.
//! - [`saltelli_design`] and [`morris_design`] build a [`Design`]: points in `[0, 1]^d`, each
//!   with a [`PointTag`] (Saltelli base row and [`Block`], or Morris trajectory and step).
//!   The Saltelli design draws on [`SobolSequence`], a Sobol' low-discrepancy sequence with
//!   Joe–Kuo direction numbers.
//! - After the runs, [`analyse`] turns the tagged points and one [`MetricColumn`] per metric
//!   into [`SensitivityRow`]s (S1, ST with bootstrap intervals; μ, μ*, σ). NaN outputs are
//!   failed runs: whole base rows or trajectories are dropped and counted, never filled.
//! - [`ishigami_check`] runs the same code on the Ishigami function against its analytic
//!   indices ([`Ishigami::analytic`]).
//!
//! The estimators themselves ([`sobol_indices`], [`morris_statistics`]) work on outputs
//! already arranged by base row or trajectory, and document their formulas and sources.

mod analyse;
mod design;
mod direction_numbers;
mod error;
mod ishigami;
mod morris_design;
mod morris_effects;
mod param_range;
mod result;
mod saltelli;
mod sobol_indices;
mod sobol_sequence;
mod stats;

pub use analyse::{MetricColumn, analyse};
pub use design::{Block, Design, DesignPoint, PointTag, SensitivityMethod};
pub use error::SensitivityError;
pub use ishigami::{
    ISHIGAMI_BASE_SAMPLES, ISHIGAMI_NAMES, ISHIGAMI_TOLERANCE, Ishigami, IshigamiCheck,
    IshigamiCheckConfig, IshigamiIndices, ishigami_check,
};
pub use morris_design::{MAX_TRAJECTORIES, morris_delta, morris_design};
pub use morris_effects::{MorrisEstimate, MorrisStep, morris_statistics, trajectory_steps};
pub use param_range::{ParamRange, map_point};
pub use result::SensitivityRow;
pub use saltelli::{MAX_BASE_SAMPLES, saltelli_design};
pub use sobol_indices::{
    IndexEstimate, SaltelliOutputs, SobolEstimate, SobolOptions, sobol_indices,
};
pub use sobol_sequence::SobolSequence;
