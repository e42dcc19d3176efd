//! Studies far larger than memory: the run count comes from the axes, a study too large is
//! refused with its count, and a shard of a huge grid runs only its own runs.

use crate::common::{assert_one_line_error, hdw, hdw_ok, json, scratch};
use std::path::Path;

/// A K̄ × Jz grid of tiny linear runs with `nk` × `nj` points.
fn grid(name: &str, nk: u64, nj: u64) -> String {
    format!(
        r#"
name = "{name}"
[base]
variant = "linear"
t_end = 0.004
[input]
kind = "sine"
voltage = 24.0
freq = 1000.0
[metrics]
keep = ["thz_amp"]
[[axis]]
name = "Kbar"
logspace = {{ start = 1e4, stop = 1e6, num = {nk} }}
[[axis]]
name = "Jz"
logspace = {{ start = 1e-4, stop = 1e-2, num = {nj} }}
"#
    )
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn a_study_too_large_to_run_is_refused_with_its_run_count() {
    let dir = scratch("scale-huge");
    let file = dir.join("huge.toml");
    std::fs::write(&file, grid("huge", 1_000_000, 1_000_000)).unwrap();
    let out = dir.join("out");
    let refused = hdw(&["study", s(&file), "--out", s(&out)]);
    assert_eq!(refused.status.code(), Some(1));
    assert_one_line_error(&refused, &["study 'huge' has 1000000000000 runs", "split it"]);
    // Refused before anything was written.
    assert!(!out.join("study.json").exists());
}

#[test]
fn a_shard_of_a_hundred_million_run_grid_runs_only_its_own_runs() {
    let dir = scratch("scale-shard");
    let file = dir.join("big.toml");
    std::fs::write(&file, grid("big", 10_000, 10_000)).unwrap();
    let out = dir.join("out");
    let done = hdw_ok(&["study", s(&file), "--out", s(&out), "--shard", "3/25000000"]);
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(err.contains("4 runs (shard 3/25000000 of 100000000)"), "{err}");
    let t = hd_io::read_table(&out.join("runs-shard-3-of-25000000.parquet")).unwrap();
    let index: Vec<f64> = t.num("run_index").unwrap().to_vec();
    assert_eq!(index, [2.0, 25_000_002.0, 50_000_002.0, 75_000_002.0]);
    // Run 75 000 002 is K̄ value 7500 (0-based) and Jz value 2 of the log grids.
    let kbar = t.num("Kbar").unwrap()[3];
    let want = 1e4 * 100f64.powf(7500.0 / 9999.0);
    assert!((kbar / want - 1.0).abs() < 1e-12, "{kbar} against {want}");
    let jz = t.num("Jz").unwrap()[3];
    assert!((jz / (1e-4 * 100f64.powf(2.0 / 9999.0)) - 1.0).abs() < 1e-12, "{jz}");
    // The plan gives the counts and a fingerprint, not a list of 1e8 runs.
    let plan = json(&out.join("study.json"));
    assert_eq!(plan["run_count"].as_u64(), Some(100_000_000));
    assert!(plan.get("runs").is_none());
    assert_eq!(plan["id_sample"].as_array().map(Vec::len), Some(65));
    // Resuming finds all four runs done and runs nothing again.
    let again = hdw_ok(&["study", s(&file), "--out", s(&out), "--shard", "3/25000000", "--resume"]);
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(err.contains("4 already done, 0 to run"), "{err}");
}

#[test]
fn resuming_with_a_changed_study_file_is_refused() {
    let dir = scratch("scale-changed");
    let file = dir.join("g.toml");
    std::fs::write(&file, grid("g", 3, 2)).unwrap();
    let out = dir.join("out");
    hdw_ok(&["study", s(&file), "--out", s(&out), "--no-report"]);
    std::fs::write(&file, grid("g", 3, 2).replace("voltage = 24.0", "voltage = 12.0")).unwrap();
    assert_one_line_error(
        &hdw(&["study", s(&file), "--out", s(&out), "--resume", "--no-report"]),
        &["does not plan", "run_index 0", "changed since the sweep began"],
    );
}
