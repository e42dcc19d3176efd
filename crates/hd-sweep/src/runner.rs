//! Running a batch of runs in parallel. A run that fails — a solver error, a bad point,
//! even a panic — becomes a failed row; the batch goes on.

use crate::row::RunRow;
use crate::study::RunSpec;
use hd_model::simulate;
use rayon::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Simulate `runs` on the current rayon pool, calling `progress` after each run (from any
/// thread). Rows come back in the order of `runs`.
pub fn run_batch(
    runs: &[RunSpec],
    decimate: usize,
    progress: &(dyn Fn(&RunRow) + Sync),
) -> Vec<RunRow> {
    runs.par_iter()
        .map(|spec| {
            let row = match catch_unwind(AssertUnwindSafe(|| simulate(&spec.config))) {
                Ok(outcome) => RunRow::new(spec, outcome, decimate),
                Err(panic) => {
                    let msg = panic
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| panic.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "unknown".to_string());
                    RunRow::panicked(spec, msg)
                }
            };
            progress(&row);
            row
        })
        .collect()
}
