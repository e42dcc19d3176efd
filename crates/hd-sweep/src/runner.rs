//! Running a batch of runs in parallel. A run that fails — a solver error, a bad point,
//! even a panic — becomes a failed row; the batch goes on.

use crate::row::RunRow;
use crate::study::RunSpec;
use hd_model::signals::Sample;
use hd_model::{SimConfig, SimError, SimOutput, simulate, simulate_streaming};
use rayon::prelude::*;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// A run handed to a [`TraceSink`]: call it once with the sink for its trace samples.
pub type TracedRun<'a> = dyn FnMut(&mut dyn FnMut(&Sample)) -> Result<SimOutput, SimError> + 'a;

/// Where kept traces go while their runs are simulated (a file per run, written as the
/// samples come), so that no trace is ever held whole in memory.
pub trait TraceSink: Sync {
    /// Run `run` (the simulation of `spec`) with a sink for its samples and return its
    /// outcome.
    fn record(&self, spec: &RunSpec, run: &mut TracedRun<'_>) -> Result<SimOutput, SimError>;
}

/// Simulate `runs` on the current rayon pool, calling `progress` after each run (from any
/// thread). Rows come back in the order of `runs`. With `traces`, the runs that keep a
/// trace stream it (every `decimate`-th sample and the last) to the sink instead of
/// holding it in their row.
pub fn run_batch(
    runs: &[RunSpec],
    decimate: usize,
    progress: &(dyn Fn(&RunRow) + Sync),
    traces: Option<&dyn TraceSink>,
) -> Vec<RunRow> {
    runs.par_iter()
        .map(|spec| {
            let one = || match traces.filter(|_| spec.config.record_trace) {
                None => simulate(&spec.config),
                Some(sink) => sink.record(spec, &mut |out| decimated(&spec.config, decimate, out)),
            };
            let row = match catch_unwind(AssertUnwindSafe(one)) {
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

/// Simulate `cfg`, handing `out` every `k`-th sample and the last (the samples
/// [`hd_model::Trace::decimate`] keeps).
fn decimated(
    cfg: &SimConfig,
    k: usize,
    out: &mut dyn FnMut(&Sample),
) -> Result<SimOutput, SimError> {
    let k = k.max(1);
    let mut j = 0usize;
    let mut skipped: Option<Sample> = None;
    let result = simulate_streaming(
        cfg,
        Some(&mut |s: &Sample| {
            if j.is_multiple_of(k) {
                out(s);
                skipped = None;
            } else {
                skipped = Some(*s);
            }
            j += 1;
        }),
    );
    if let Some(last) = skipped {
        out(&last);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use hd_model::Trace;

    #[test]
    fn streamed_decimation_keeps_what_trace_decimate_keeps() {
        let cfg = SimConfig { t_end: 0.013, record_trace: true, ..SimConfig::default() };
        let full = simulate(&cfg).unwrap().trace.unwrap();
        for k in [1, 2, 3, 7] {
            let mut streamed = Trace::default();
            decimated(&cfg, k, &mut |s| streamed.push(s)).unwrap();
            let want = full.decimate(k);
            assert_eq!(streamed.len(), want.len(), "k = {k}");
            // Bit for bit (open-loop runs hold NaN in the controller's columns).
            let same =
                |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(streamed.columns().zip(want.columns()).all(|(a, b)| same(a, b)), "k = {k}");
        }
    }
}
