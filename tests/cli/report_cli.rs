//! End-to-end tests of `hdw report`: shards made by hand (no scheduler) merged into the
//! same outputs as one machine's `hdw study`; missing, duplicated, failed and foreign runs.

use crate::common::*;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Nine quick runs (damped variant, 40 ms each).
const NINE: &str = r#"
name = "nine"
[base]
variant = "damped"
t_end = 0.04
[metrics]
keep = ["thz_amp", "thz_ripple", "efficiency"]
[[axis]]
name = "Kbar"
values = [2e5, 7.8e5, 2e6]
[[axis]]
name = "voltage"
values = [12, 24, 36]
"#;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The study file in `dir`, and `n` shards of it run into `dir/out`.
fn sharded(dir: &Path, text: &str, n: usize) -> (PathBuf, PathBuf) {
    let file = dir.join("study.toml");
    std::fs::write(&file, text).unwrap();
    let out = dir.join("out");
    for k in 1..=n {
        hdw_ok(&["study", s(&file), "--out", s(&out), "--shard", &format!("{k}/{n}")]);
    }
    (file, out)
}

fn ids(t: &hd_io::Table) -> Vec<String> {
    t.text("run_id").unwrap().iter().map(|v| v.clone().unwrap()).collect()
}

fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn merged_shards_give_the_report_of_one_machine() {
    let dir = scratch("report-same");
    let (file, out) = sharded(&dir, NINE, 3);
    let single = dir.join("single");
    hdw_ok(&["study", s(&file), "--out", s(&single)]);
    hdw_ok(&["report", s(&out)]);

    let a = hd_io::read_table(&single.join("runs.parquet")).unwrap();
    let b = hd_io::read_table(&out.join("runs.parquet")).unwrap();
    assert_eq!(ids(&a), ids(&b), "same runs in the same order");
    assert_eq!(a.names, b.names);
    for m in ["run_index", "Kbar", "voltage", "thz_amp", "thz_ripple", "efficiency"] {
        let (x, y) = (a.num(m).unwrap(), b.num(m).unwrap());
        assert!(x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits()), "{m}: {x:?} vs {y:?}");
    }
    for name in ["report.md", "study.json", "nine-nine-thz_amp.svg", "nine-nine-efficiency.svg"] {
        let x = std::fs::read(single.join(name)).unwrap();
        let y = std::fs::read(out.join(name)).unwrap();
        assert!(x == y, "{name} differs between one machine and merged shards");
    }
    // The merged shard tables move to shards/: the folder holds each run once.
    let tables: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("runs"))
        .collect();
    assert_eq!(tables, ["runs.parquet"]);
    assert!(out.join("shards/runs-shard-3-of-3.parquet").exists());
    let counted = ok(&hdw(&["explore", s(&out), "--group-by", "part", "--format", "csv"]));
    assert_eq!(counted.lines().nth(1), Some("nine,9,0"), "{counted}");
    // Running it again reads the shards, not its own merged table: nothing counts twice.
    let again = hdw_ok(&["report", s(&out)]);
    assert!(stderr(&again).contains("9 rows, 0 duplicate rows"), "{}", stderr(&again));
}

#[test]
fn missing_runs_are_an_error_that_names_them_unless_allowed() {
    let dir = scratch("report-missing");
    let (_, out) = sharded(&dir, NINE, 3);
    let plan = json(&out.join("study.json"));
    let lost: Vec<String> = [1, 4, 7]
        .iter()
        .map(|&k| plan["runs"][k]["run_id"].as_str().unwrap().to_string())
        .collect();
    std::fs::remove_file(out.join("runs-shard-2-of-3.parquet")).unwrap();

    let refused = hdw(&["report", s(&out)]);
    assert_one_line_error(
        &refused,
        &[
            "3 of 9 planned runs are missing",
            "index 1 (id",
            "index 7",
            "--shard 2/3 --resume",
            "--allow-missing",
        ],
    );
    for id in &lost {
        assert!(stderr(&refused).contains(id.as_str()), "error names {id}");
    }
    assert!(!out.join("report.md").exists() && !out.join("runs.parquet").exists());

    hdw_ok(&["report", s(&out), "--allow-missing"]);
    let t = hd_io::read_table(&out.join("runs.parquet")).unwrap();
    let present: BTreeSet<String> = ids(&t).into_iter().collect();
    assert_eq!(present.len(), 6);
    assert!(lost.iter().all(|id| !present.contains(id)));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("**Incomplete:** 3 of 9 planned runs are missing"), "{md}");
    assert!(lost.iter().all(|id| md.contains(id.as_str())), "report.md lists the missing runs");
}

#[test]
fn duplicated_runs_are_kept_once() {
    let dir = scratch("report-dupes");
    let (file, out) = sharded(&dir, NINE, 2);
    // An earlier layout of the same study (shard 1 of 3) and a leftover part of shard 1 of 2
    // repeat runs already in the final shard tables.
    hdw_ok(&["study", s(&file), "--out", s(&out), "--shard", "1/3"]);
    std::fs::create_dir_all(out.join("parts")).unwrap();
    std::fs::copy(
        out.join("runs-shard-1-of-2.parquet"),
        out.join("parts/runs-shard-1-of-2-000009.parquet"),
    )
    .unwrap();
    let done = hdw_ok(&["report", s(&out)]);
    // Rows: 5 + 4 (shards of 2) + 3 (shard 1 of 3) + 5 (the leftover part).
    assert!(stderr(&done).contains("17 rows, 8 duplicate rows"), "{}", stderr(&done));
    let t = hd_io::read_table(&out.join("runs.parquet")).unwrap();
    assert_eq!(t.height, 9);
    assert_eq!(ids(&t).into_iter().collect::<BTreeSet<_>>().len(), 9);
    let index = t.num("run_index").unwrap();
    assert!(index.iter().enumerate().all(|(k, &i)| i == k as f64), "sorted by run_index");
}

#[test]
fn failed_runs_are_reported_and_foreign_runs_refused() {
    let dir = scratch("report-failed");
    let text = FAILING_STUDY;
    let (_, out) = sharded(&dir, text, 2);
    let done = hdw_ok(&["report", s(&out)]);
    assert!(stderr(&done).contains("failed: index 1 (id"), "{}", stderr(&done));
    assert!(stderr(&done).contains("3 of 3 planned runs"), "{}", stderr(&done));

    // Shards of another study in the same folder would mix two studies in one report.
    // `hdw study` refuses to run another study into the folder …
    let other = dir.join("other.toml");
    std::fs::write(&other, NINE).unwrap();
    let r = hdw(&["study", s(&other), "--out", s(&out), "--shard", "3/3"]);
    assert_one_line_error(&r, &["holds the results of study 'failing', not 'nine'"]);
    // … and a shard table copied in from elsewhere is refused by the report.
    let elsewhere = dir.join("elsewhere");
    hdw_ok(&["study", s(&other), "--out", s(&elsewhere), "--shard", "3/3"]);
    let shard = "runs-shard-3-of-3.parquet";
    std::fs::copy(elsewhere.join(shard), out.join(shard)).unwrap();
    let refused = hdw(&["report", s(&out)]);
    assert_one_line_error(&refused, &["rows belong to no run of", "runs-shard-3-of-3.parquet"]);
}

#[test]
fn a_folder_without_a_plan_or_with_a_changed_study_file_is_refused() {
    let dir = scratch("report-refused");
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    assert_one_line_error(&hdw(&["report", s(&empty)]), &["study.json", "--out folder"]);
    assert_one_line_error(
        &hdw(&["report", s(&dir.join("nowhere"))]),
        &["nowhere", "no such folder"],
    );

    let (file, out) = sharded(&dir, NINE, 2);
    std::fs::write(&file, NINE.replace("2e6", "3e6")).unwrap();
    assert_one_line_error(
        &hdw(&["report", s(&out)]),
        &["study.toml", "changed since the sweep", "--study"],
    );
    // The original text under another name, given with --study, is accepted.
    let kept = dir.join("kept.toml");
    std::fs::write(&kept, NINE).unwrap();
    hdw_ok(&["report", s(&out), "--study", s(&kept)]);
}

#[test]
fn a_design_study_gets_its_sensitivity_analysis_from_the_shards() {
    let dir = scratch("report-morris");
    let text = r#"
name = "tiny-morris"
[base]
variant = "full"
t_end = 0.04
[input]
kind = "sine"
voltage = 24.0
freq = 50.0
[metrics]
keep = ["thz_amp", "efficiency"]
cycles = 1
[sample]
method = "morris"
trajectories = 8
seed = 4
[[sample.param]]
name = "Km"
lo = 0.4
hi = 0.65
[[sample.param]]
name = "Jz"
lo = 1e-4
hi = 0.05
log = true
"#;
    let (file, out) = sharded(&dir, text, 3);
    let single = dir.join("single");
    hdw_ok(&["study", s(&file), "--out", s(&single)]);
    let done = hdw_ok(&["report", s(&out)]);
    assert!(stderr(&done).contains("sensitivity (morris, thz_amp)"), "{}", stderr(&done));
    assert!(out.join("sensitivity.parquet").exists());
    for name in ["report.md", "sensitivity.md"] {
        let x = std::fs::read_to_string(single.join(name)).unwrap();
        let y = std::fs::read_to_string(out.join(name)).unwrap();
        assert_eq!(x, y, "{name} differs between one machine and merged shards");
    }
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("## Global sensitivity"), "{md}");
}

#[test]
fn kept_traces_of_the_shards_are_merged_too() {
    let dir = scratch("report-traces");
    let text = NINE.replace("[metrics]", "[traces]\nkeep = true\ndecimate = 10\n[metrics]");
    let (file, out) = sharded(&dir, &text, 2);
    let single = dir.join("single");
    hdw_ok(&["study", s(&file), "--out", s(&single)]);
    hdw_ok(&["report", s(&out)]);
    let count = |d: &Path| {
        ok(&hdw(&[
            "explore",
            s(d),
            "--traces",
            "--group-by",
            "run_id",
            "--agg",
            "t:count",
            "--format",
            "csv",
        ]))
    };
    assert_eq!(count(&single), count(&out), "same samples of the same runs");
    assert!(out.join("shards/traces-shard-2-of-2.parquet").exists());
    let plot = "nine-nine-theta_z-traces.svg";
    assert_eq!(std::fs::read(single.join(plot)).unwrap(), std::fs::read(out.join(plot)).unwrap());
}
