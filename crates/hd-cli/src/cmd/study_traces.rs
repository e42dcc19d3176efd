//! Kept traces of a study, streamed: each run writes its samples to a file of its own as
//! the solve produces them (a temporary in `parts/`), and a committed part stacks them a
//! window of rows at a time. Memory does not grow with the traces' length.

use anyhow::{Result, bail};
use hd_io::atomic::Staged;
use hd_io::store::RunStore;
use hd_io::{IoError, stream_trace_into};
use hd_model::{SimError, SimOutput, TRACE_COLUMNS};
use hd_sweep::{RunPlan, RunSpec, TraceSink, TracedRun};
use std::sync::Mutex;

/// The trace files of one part's runs, filled from the worker threads.
pub struct TraceFiles<'a> {
    store: &'a RunStore,
    written: Mutex<Vec<(usize, Staged)>>,
    failed: Mutex<Option<IoError>>,
}

impl<'a> TraceFiles<'a> {
    /// For the runs of one part of `store`'s sweep.
    pub fn new(store: &'a RunStore) -> Self {
        Self { store, written: Mutex::new(Vec::new()), failed: Mutex::new(None) }
    }

    /// The written files in run order, or the first write error (the part is then not
    /// committed and a resumed sweep runs it again).
    pub fn finish(self) -> Result<Vec<Staged>> {
        let failed = self.failed.into_inner().unwrap_or_else(|p| p.into_inner());
        if let Some(e) = failed {
            return Err(anyhow::Error::new(e).context("cannot write a kept trace"));
        }
        let mut written = self.written.into_inner().unwrap_or_else(|p| p.into_inner());
        written.sort_by_key(|(index, _)| *index);
        Ok(written.into_iter().map(|(_, s)| s).collect())
    }
}

impl TraceSink for TraceFiles<'_> {
    fn record(&self, spec: &RunSpec, run: &mut TracedRun<'_>) -> Result<SimOutput, SimError> {
        let mut staged = match Staged::new(&self.store.trace_scratch(spec.index)) {
            Ok(s) => s,
            Err(e) => {
                let message = e.to_string();
                self.failed.lock().unwrap_or_else(|p| p.into_inner()).get_or_insert(e);
                return Err(SimError::Panic(format!("trace not written: {message}")));
            }
        };
        match stream_trace_into(&mut staged, Some(&spec.run_id), |sink| run(sink)) {
            Ok(Ok(out)) => {
                self.written.lock().unwrap_or_else(|p| p.into_inner()).push((spec.index, staged));
                Ok(out)
            }
            // A failed run keeps no trace (its temporary goes with `staged`).
            Ok(Err(e)) => Err(e),
            Err(e) => {
                let message = e.to_string();
                self.failed.lock().unwrap_or_else(|p| p.into_inner()).get_or_insert(e);
                Err(SimError::Panic(format!("trace not written: {message}")))
            }
        }
    }
}

/// Refuse a study whose kept traces (shard `k` of `n`, every `decimate`-th sample) would
/// hold more than `limit` values (0: no limit), before any run starts.
pub fn check_traces_size(
    plan: &RunPlan,
    k: u64,
    n: u64,
    decimate: usize,
    limit: u64,
) -> Result<()> {
    if limit == 0 {
        return Ok(());
    }
    let columns = (TRACE_COLUMNS.len() + 1) as f64;
    let mut values = 0.0;
    for i in plan.shard_indices(k, n) {
        let cfg = plan.spec(i).config;
        let samples = (cfg.t_end / cfg.output_interval()).floor() + 1.0;
        values += (samples / decimate.max(1) as f64).ceil() * columns;
        if values.is_nan() || values > limit as f64 {
            bail!(
                "the kept traces would hold more than {limit} values (over {values:.3e} by run {i}): raise [traces] decimate or dt_out, keep fewer runs' traces, or lift the limit with --max-output-values N (0 = none)"
            );
        }
    }
    Ok(())
}
