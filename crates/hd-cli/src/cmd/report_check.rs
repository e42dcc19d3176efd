//! The merged runs of a study folder checked against the study's plan (`study.json`):
//! which planned runs have no row (missing), which rows belong to no planned run (foreign),
//! and which runs failed.

use super::study_json::PlannedRun;
use std::collections::{BTreeSet, HashMap, HashSet};
use std::fmt::Write as _;

/// How many runs a one-line list names before it says "and N more".
pub const LIST_LIMIT: usize = 12;

/// A run whose row says `status = failed`.
#[derive(Clone, Debug, PartialEq)]
pub struct FailedRun {
    /// The planned run.
    pub run: PlannedRun,
    /// The error recorded for it.
    pub error: String,
}

/// The outcome of the check.
#[derive(Debug, Default)]
pub struct Check {
    /// Planned runs with no row, in index order.
    pub missing: Vec<PlannedRun>,
    /// Run ids of rows that the plan does not hold, in table order.
    pub foreign: Vec<String>,
    /// Planned runs whose row failed, in index order.
    pub failed: Vec<FailedRun>,
}

/// Compare the merged rows (`ids`, `status` and `error` columns, one row per run) with the
/// planned runs.
pub fn check(
    plan: &[PlannedRun],
    ids: &[Option<String>],
    status: &[Option<String>],
    error: &[Option<String>],
) -> Check {
    let present: HashMap<&str, usize> =
        ids.iter().enumerate().filter_map(|(k, id)| Some((id.as_deref()?, k))).collect();
    let planned: HashSet<&str> = plan.iter().map(|r| r.run_id.as_str()).collect();
    let mut out = Check::default();
    for run in plan {
        match present.get(run.run_id.as_str()) {
            None => out.missing.push(run.clone()),
            Some(&k) if status.get(k).and_then(|s| s.as_deref()) != Some("ok") => {
                let error = error.get(k).cloned().flatten().unwrap_or_default();
                out.failed.push(FailedRun { run: run.clone(), error });
            }
            Some(_) => {}
        }
    }
    out.missing.sort_by_key(|r| r.index);
    out.failed.sort_by_key(|f| f.run.index);
    out.foreign =
        ids.iter().flatten().filter(|id| !planned.contains(id.as_str())).cloned().collect();
    out
}

/// `index 3 (id 9f…, part p), …` for at most [`LIST_LIMIT`] runs, then `and N more`.
pub fn list_runs(runs: &[PlannedRun]) -> String {
    let mut text: Vec<String> = runs
        .iter()
        .take(LIST_LIMIT)
        .map(|r| format!("index {} (id {}, part {})", r.index, r.run_id, r.part))
        .collect();
    if runs.len() > LIST_LIMIT {
        text.push(format!("and {} more", runs.len() - LIST_LIMIT));
    }
    text.join(", ")
}

/// The shards (1-based K of `n`) that hold the given runs: run `i` is in shard `i mod n + 1`.
pub fn shards_of(runs: &[PlannedRun], n: usize) -> Vec<usize> {
    let set: BTreeSet<usize> = runs.iter().map(|r| r.index % n.max(1) + 1).collect();
    set.into_iter().collect()
}

/// The note placed in `report.md` of an incomplete set: the count and every missing run.
pub fn missing_note(missing: &[PlannedRun], planned: usize) -> String {
    let mut md = format!(
        "**Incomplete:** {} of {planned} planned runs are missing from the results (reported \
         with `--allow-missing`); the tables and plots below cover the runs present.\n\n\
         | run_index | run_id | part |\n|---:|---|---|\n",
        missing.len()
    );
    for r in missing {
        let _ = writeln!(md, "| {} | `{}` | {} |", r.index, r.run_id, r.part);
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(index: usize) -> PlannedRun {
        PlannedRun { run_id: format!("id{index}"), index, part: "p".into() }
    }

    fn some(v: &[&str]) -> Vec<Option<String>> {
        v.iter().map(|s| Some(s.to_string())).collect()
    }

    #[test]
    fn missing_foreign_and_failed_runs_are_told_apart() {
        let plan: Vec<PlannedRun> = (0..5).map(run).collect();
        let ids = some(&["id4", "id0", "idX", "id2"]);
        let status = some(&["ok", "failed", "ok", "ok"]);
        let error = vec![None, Some("too many steps".into()), None, None];
        let c = check(&plan, &ids, &status, &error);
        assert_eq!(c.missing, [run(1), run(3)]);
        assert_eq!(c.foreign, ["idX"]);
        assert_eq!(c.failed, [FailedRun { run: run(0), error: "too many steps".into() }]);
    }

    #[test]
    fn long_lists_are_cut_and_shards_are_named_once() {
        let runs: Vec<PlannedRun> = (0..20).map(|k| run(4 * k + 2)).collect();
        let text = list_runs(&runs);
        assert!(text.starts_with("index 2 (id id2, part p), index 6"), "{text}");
        assert!(text.ends_with("and 8 more"), "{text}");
        assert_eq!(shards_of(&runs, 4), [3]);
        assert_eq!(shards_of(&[run(0), run(5)], 4), [1, 2]);
        let note = missing_note(&runs[..1], 9);
        assert!(note.contains("1 of 9 planned runs") && note.contains("| 2 | `id2` | p |"));
    }
}
