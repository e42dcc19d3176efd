//! The output folder of a sweep, committed in parts so that a sweep killed at any moment
//! loses nothing already committed and a resumed sweep runs each missing run exactly once.
//!
//! Layout of `DIR`:
//! - `runs.parquet` (or `runs-shard-K-of-N.parquet` for a shard): the final table;
//! - `traces.parquet` (or `traces-shard-K-of-N.parquet`): kept traces, long format;
//! - `parts/`: part files committed while the sweep runs (`runs-TAG-SEQ.parquet`, with
//!   matching `traces-TAG-SEQ.parquet`), merged into the final files and removed at the end.
//!
//! Every file is written to a temporary name and renamed, so each part is all or nothing.

use crate::error::IoError;
use crate::parquet_out::write_out_table;
use crate::runs::{concat_files_into, for_each_run, merge_runs_into, read_run_ids};
use hd_model::OutTable;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// One sweep's output folder, for one shard (or the whole study).
pub struct RunStore {
    dir: PathBuf,
    tag: String,
    next_seq: usize,
}

impl RunStore {
    /// Open `dir` for the shard `shard = Some((k, n))` or the whole study.
    pub fn open(dir: &Path, shard: Option<(usize, usize)>) -> Result<Self, IoError> {
        // `parts/` is created by the first commit: a refused or failed start leaves no
        // empty folder behind.
        let tag = match shard {
            Some((k, n)) => format!("shard-{k}-of-{n}"),
            None => "all".to_string(),
        };
        let mut store = RunStore { dir: dir.to_path_buf(), tag, next_seq: 0 };
        store.next_seq = store.part_files("runs")?.len();
        Ok(store)
    }

    /// Path of the final runs table of this shard.
    pub fn runs_path(&self) -> PathBuf {
        self.final_path("runs")
    }

    /// Path of the final traces table of this shard.
    pub fn traces_path(&self) -> PathBuf {
        self.final_path("traces")
    }

    fn final_path(&self, kind: &str) -> PathBuf {
        if self.tag == "all" {
            self.dir.join(format!("{kind}.parquet"))
        } else {
            self.dir.join(format!("{kind}-{}.parquet", self.tag))
        }
    }

    /// Part files of `kind` (runs or traces) of this shard, in commit order.
    fn part_files(&self, kind: &str) -> Result<Vec<PathBuf>, IoError> {
        let parts = self.dir.join("parts");
        let prefix = format!("{kind}-{}-", self.tag);
        let entries = match std::fs::read_dir(&parts) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => return Err(IoError::fs(&parts, e)),
        };
        let mut files: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with(&prefix) && n.ends_with(".parquet"))
            })
            .collect();
        files.sort();
        Ok(files)
    }

    /// Whether anything of this shard is already in the folder.
    pub fn has_results(&self) -> Result<bool, IoError> {
        Ok(self.runs_path().exists() || !self.part_files("runs")?.is_empty())
    }

    /// Call `visit(run_index, run_id)` for every run already committed (final table and
    /// parts), one file at a time. Part files whose runs are all in the final table were
    /// merged before an interruption and are removed here.
    pub fn committed_runs(&mut self, visit: &mut dyn FnMut(u64, &str)) -> Result<(), IoError> {
        let final_ids = if self.runs_path().exists() {
            for_each_run(&self.runs_path(), visit)?;
            read_run_ids(&[self.runs_path()])?
        } else {
            HashSet::new()
        };
        for f in self.part_files("runs")? {
            let part_ids = read_run_ids(std::slice::from_ref(&f))?;
            if !final_ids.is_empty() && part_ids.is_subset(&final_ids) {
                let traces = self.traces_twin(&f);
                let _ = std::fs::remove_file(&traces);
                std::fs::remove_file(&f).map_err(|e| IoError::fs(&f, e))?;
            } else {
                for_each_run(&f, visit)?;
            }
        }
        self.next_seq = self.next_seq.max(self.part_files("runs")?.len());
        Ok(())
    }

    /// Run ids already committed (final table and parts). Part files whose runs are all in
    /// the final table were merged before an interruption and are removed here.
    pub fn committed_ids(&mut self) -> Result<HashSet<String>, IoError> {
        let final_ids = if self.runs_path().exists() {
            read_run_ids(&[self.runs_path()])?
        } else {
            HashSet::new()
        };
        let mut ids = final_ids.clone();
        for f in self.part_files("runs")? {
            let part_ids = read_run_ids(std::slice::from_ref(&f))?;
            if !final_ids.is_empty() && part_ids.is_subset(&final_ids) {
                let traces = self.traces_twin(&f);
                let _ = std::fs::remove_file(&traces);
                std::fs::remove_file(&f).map_err(|e| IoError::fs(&f, e))?;
            } else {
                ids.extend(part_ids);
            }
        }
        self.next_seq = self.next_seq.max(self.part_files("runs")?.len());
        Ok(ids)
    }

    fn traces_twin(&self, runs_part: &Path) -> PathBuf {
        let name = runs_part.file_name().and_then(|n| n.to_str()).unwrap_or("");
        runs_part.with_file_name(name.replacen("runs-", "traces-", 1))
    }

    /// Where the kept trace of run `run_index` is streamed before its part is committed
    /// (its temporary, `.traces-TAG-run-INDEX.tmp-…`, is removed with this shard's others).
    pub fn trace_scratch(&self, run_index: usize) -> PathBuf {
        self.dir.join("parts").join(format!("traces-{}-run-{run_index}.parquet", self.tag))
    }

    /// Commit a batch of runs as one part whose kept traces were streamed to the Parquet
    /// files `trace_files` (one per run, in run order; see [`Self::trace_scratch`]): they
    /// are stacked a window of rows at a time into the part's traces table, then the runs
    /// table that makes the batch count as done is written.
    pub fn commit_streamed(
        &mut self,
        runs: &OutTable,
        trace_files: &[PathBuf],
    ) -> Result<(), IoError> {
        if runs.height() == 0 {
            return Ok(());
        }
        let path = self.next_part_path();
        if !trace_files.is_empty() {
            let mut staged = crate::atomic::Staged::new(&self.traces_twin(&path))?;
            crate::runs::concat_files_into(trace_files, &mut staged)?;
            crate::atomic::commit(vec![staged], &[])?;
        }
        write_out_table(&path, runs)
    }

    /// The path of the next runs part.
    fn next_part_path(&mut self) -> PathBuf {
        // Sequence numbers are zero-padded so that name order is commit order; skip any
        // number already taken (parts left by an earlier, interrupted process).
        let parts = self.dir.join("parts");
        loop {
            let path = parts.join(format!("runs-{}-{:06}.parquet", self.tag, self.next_seq));
            self.next_seq += 1;
            if !path.exists() {
                return path;
            }
        }
    }

    /// Commit a batch of runs as one part: its traces table (if any rows kept one) first,
    /// then the runs table that makes the batch count as done.
    pub fn commit(&mut self, runs: &OutTable, traces: Option<&OutTable>) -> Result<(), IoError> {
        if runs.height() == 0 {
            return Ok(());
        }
        let path = self.next_part_path();
        if let Some(t) = traces.filter(|t| t.height() > 0) {
            write_out_table(&self.traces_twin(&path), t)?;
        }
        write_out_table(&path, runs)
    }

    /// Merge the final table (if any) and all parts into the final files, then remove the
    /// parts. Returns the number of runs in the final table.
    pub fn finish(&mut self) -> Result<usize, IoError> {
        let run_parts = self.part_files("runs")?;
        let trace_parts = self.part_files("traces")?;
        let mut run_inputs = Vec::new();
        if self.runs_path().exists() {
            run_inputs.push(self.runs_path());
        }
        run_inputs.extend(run_parts.iter().cloned());
        // The merged runs and traces tables land together (one group of renames that an
        // interrupt cannot split): a runs table that counts the parts as merged never stands
        // beside a traces table that lacks their traces, which a resume would then drop.
        let mut staged = Vec::new();
        if !trace_parts.is_empty() {
            let mut trace_inputs = Vec::new();
            if self.traces_path().exists() {
                trace_inputs.push(self.traces_path());
            }
            trace_inputs.extend(trace_parts.iter().cloned());
            let mut traces = crate::atomic::Staged::new(&self.traces_path())?;
            concat_files_into(&trace_inputs, &mut traces)?;
            staged.push(traces);
        }
        let mut runs = crate::atomic::Staged::new(&self.runs_path())?;
        let n = merge_runs_into(&run_inputs, &mut runs)?;
        if n > 0 {
            staged.push(runs);
        }
        crate::atomic::commit(staged, &[])?;
        for f in run_parts.iter().chain(&trace_parts) {
            std::fs::remove_file(f).map_err(|e| IoError::fs(f, e))?;
        }
        let parts = self.dir.join("parts");
        // Half-written temporaries of this shard's killed writers (never renamed, so never
        // counted); other shards' files are left alone.
        let own = [format!(".runs-{}-", self.tag), format!(".traces-{}-", self.tag)];
        if let Ok(entries) = std::fs::read_dir(&parts) {
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                if own.iter().any(|p| name.starts_with(p)) && name.contains(".tmp-") {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        // Only succeeds once empty: another shard's parts may still be there.
        let _ = std::fs::remove_dir(&parts);
        Ok(n)
    }
}
