//! One module per subcommand.

pub mod batching;
pub mod common;
pub mod control_args;
pub mod datasheet;
pub mod envelope;
pub mod explore;
pub mod export;
pub mod fit;
pub mod fit_drive;
pub mod fit_drive_out;
pub mod fit_hysteresis;
pub mod fit_input;
pub mod fit_progress;
pub mod model_args;
pub mod plot;
pub mod report;
pub mod report_check;
pub mod report_inputs;
pub mod sensitivity;
pub mod sim_progress;
pub mod simulate;
pub mod study;
pub mod study_json;
pub mod study_traces;
pub mod synth;
pub mod synth_drive;
