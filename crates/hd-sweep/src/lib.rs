//! The sweep engine: study files (`studies/*.toml`) checked into a [`Study`], generated run by
//! run as [`RunSpec`]s ([`RunPlan`]), and run in parallel with rayon into [`RunRow`]s.
//!
//! Main items: [`load_study`], [`Study::expand`], [`run_batch`], [`RunRow`], [`StudyError`].

pub mod axis;
pub mod design;
pub mod error;
pub mod manifest;
pub mod parse;
pub mod plan;
pub mod row;
pub mod runner;
pub mod sensitivity;
pub mod spec;
pub mod study;
pub mod tables;

pub use error::StudyError;
pub use manifest::StudyManifest;
pub use parse::{load_study, parse_study};
pub use plan::{MAX_RUNS, RunPlan, TooManyRuns};
pub use row::{RunRow, RunStatus};
pub use runner::{TraceSink, TracedRun, run_batch};
pub use study::{RunSpec, Study};
