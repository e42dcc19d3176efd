//! End-to-end tests of the `hdw` binary, in one test binary so polars is linked once.

mod common;
mod datasheet_cli;
mod docs;
mod explore_cli;
mod export_cli;
mod fault_injection;
mod fit_bad_data;
mod fit_cli;
mod fit_compliant_cli;
mod fit_compliant_loop_cli;
mod fit_drive_cli;
mod fit_drive_refusals;
mod fit_drive_series;
mod fit_laws;
mod fit_nested;
mod fit_rig_files;
mod fit_shipped_data;
mod refusals;
mod report_cli;
mod sensitivity_cli;
mod shipped_studies;
mod simulate_cli;
mod stiffness_cli;
mod study_cli;
mod sweep_scale;
mod synth_drive_cli;
