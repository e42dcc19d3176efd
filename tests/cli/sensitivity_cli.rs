//! End-to-end tests of global sensitivity through the `hdw` binary: a tiny Sobol' study
//! and a tiny Morris study, runs that fail, runs that are missing, and the argument rules.

use crate::common::*;

use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Write `text` as a study file in a fresh folder, run it, return the output folder.
fn run_study(name: &str, text: &str, extra: &[&str]) -> PathBuf {
    let dir = scratch(name);
    let file = dir.join("study.toml");
    std::fs::write(&file, text).unwrap();
    let out = dir.join("out");
    let mut args = vec!["study", file.to_str().unwrap(), "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    ok(&hdw(&args));
    out
}

fn json_of(dir: &Path, extra: &[&str]) -> Value {
    let mut args = vec!["sensitivity", dir.to_str().unwrap(), "--format", "json"];
    args.extend_from_slice(extra);
    serde_json::from_str(&ok(&hdw(&args))).expect("one JSON document")
}

/// Full model at 24 V, 50 Hz for two drive cycles; `sample` is the [sample] section.
fn study(name: &str, solver: &str, sample: &str) -> String {
    format!(
        r#"name = "{name}"
[base]
variant = "full"
t_end = 0.04
[input]
kind = "sine"
voltage = 24.0
freq = 50.0
[solver]
{solver}
[metrics]
keep = ["thz_amp", "efficiency"]
cycles = 1
{sample}
[[sample.param]]
name = "Km"
lo = 0.4
hi = 0.65
[[sample.param]]
name = "Jz"
lo = 1e-4
hi = 0.05
log = true
"#
    )
}

const SOBOL: &str = "[sample]\nmethod = \"sobol\"\nn = 32\nseed = 1";

#[test]
fn sensitivity_of_a_sobol_study_end_to_end() {
    let dir = run_study("sobol", &study("tiny-sobol", "", SOBOL), &[]);
    // The study ran the analysis by itself.
    for f in ["sensitivity.parquet", "sensitivity.md", "sensitivity-thz_amp.svg"] {
        assert!(dir.join(f).exists(), "{f} is written at the end of the study");
    }
    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(report.contains("## Global sensitivity"));

    // Design columns of runs.parquet.
    let runs = hd_io::read_table(&dir.join("runs.parquet")).unwrap();
    assert_eq!(runs.height, 32 * 4);
    let tail: Vec<&str> = runs.names.iter().rev().take(5).rev().map(String::as_str).collect();
    assert_eq!(tail, ["design_method", "design_group", "design_slot", "u_Km", "u_Jz"]);
    assert!(runs.text("design_method").unwrap().iter().all(|m| m.as_deref() == Some("sobol")));
    let (group, slot) = (runs.num("design_group").unwrap(), runs.num("design_slot").unwrap());
    for k in 0..runs.height {
        assert_eq!((group[k], slot[k]), ((k / 4) as f64, (k % 4) as f64));
    }
    let (u, km) = (runs.num("u_Km").unwrap(), runs.num("Km").unwrap());
    assert!(u.iter().zip(km).all(|(u, km)| (km - (0.4 + 0.25 * u)).abs() < 1e-12));

    // The command on the folder: JSON structure and the table.
    let doc = json_of(&dir, &["--bootstrap", "100", "--metrics", "thz_amp,efficiency"]);
    assert_eq!(doc["study"], "tiny-sobol");
    let part = &doc["parts"][0];
    assert_eq!(part["method"], "sobol");
    assert_eq!(part["parameters"], serde_json::json!(["Km", "Jz"]));
    assert_eq!((part["groups"].as_u64(), part["runs"].as_u64()), (Some(32), Some(128)));
    assert_eq!((part["failed"].as_u64(), part["missing"].as_u64()), (Some(0), Some(0)));
    let rows = doc["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2 * 2);
    for r in rows {
        for key in ["S1", "S1_lo", "S1_hi", "ST", "ST_lo", "ST_hi"] {
            assert!(r[key].is_f64(), "{key} in {r}");
        }
        assert!(r["mu_star"].is_null(), "Morris columns are null for Sobol' rows");
        assert_eq!((r["n_used"].as_u64(), r["n_dropped"].as_u64()), (Some(32), Some(0)));
    }
    let ranking = doc["ranking"].as_array().unwrap();
    assert_eq!(ranking.len(), 2);
    let names: BTreeSet<&str> =
        ranking[0]["order"].as_array().unwrap().iter().filter_map(Value::as_str).collect();
    assert_eq!(names, BTreeSet::from(["Km", "Jz"]));
    // Motor torque constant drives the amplitude far more than the load inertia here.
    assert_eq!(ranking[0]["metric"], "thz_amp");
    assert_eq!(ranking[0]["order"][0], "Km");

    let table = hd_io::read_table(&dir.join("sensitivity.parquet")).unwrap();
    assert_eq!(table.height, 4);
    for c in ["part", "method", "parameter", "metric", "S1", "ST_hi", "mu_star", "n_dropped"] {
        assert!(table.names.iter().any(|n| n == c), "column {c}");
    }
}

#[test]
fn sensitivity_failed_runs_drop_whole_base_rows_and_are_counted() {
    // Calibrate on the solver at hand: run the design once, then again with max_steps at
    // the 90th percentile of the work (accepted + rejected steps) the runs needed, so
    // that the costliest tenth of the runs fails.
    let free = run_study("calibrate", &study("calibrate", "", SOBOL), &["--no-report"]);
    let t = hd_io::read_table(&free.join("runs.parquet")).unwrap();
    let (steps, rejected) = (t.num("steps").unwrap(), t.num("rejected_steps").unwrap());
    let mut work: Vec<f64> = steps.iter().zip(rejected).map(|(s, r)| s + r).collect();
    work.sort_by(f64::total_cmp);
    let limit = format!("max_steps = {}", work[work.len() * 9 / 10] as u64);
    let dir = run_study("failing", &study("failing", &limit, SOBOL), &[]);

    let runs = hd_io::read_table(&dir.join("runs.parquet")).unwrap();
    let status = runs.text("status").unwrap();
    let group = runs.num("design_group").unwrap();
    let failed_groups: BTreeSet<u64> = (0..runs.height)
        .filter(|&i| status[i].as_deref() != Some("ok"))
        .map(|i| group[i] as u64)
        .collect();
    assert!(!failed_groups.is_empty() && failed_groups.len() < 32, "{limit}: {failed_groups:?}");
    eprintln!("{limit}: {} of 32 base rows have a failed run", failed_groups.len());

    let doc = json_of(&dir, &["--bootstrap", "50"]);
    let failed = status.iter().filter(|s| s.as_deref() != Some("ok")).count();
    assert_eq!(doc["parts"][0]["failed"].as_u64(), Some(failed as u64));
    let used = 32 - failed_groups.len() as u64;
    for r in doc["rows"].as_array().unwrap() {
        assert_eq!(r["n_dropped"].as_u64(), Some(failed_groups.len() as u64), "{r}");
        assert_eq!(r["n_used"].as_u64(), Some(used));
        // Indices come from the rows that remain, or are null with a note when too few do.
        if used >= 16 {
            assert!(r["ST"].is_f64(), "{r}");
        } else {
            assert!(r["ST"].is_null() && r["note"].is_string(), "{r}");
        }
    }
    let md = std::fs::read_to_string(dir.join("sensitivity.md")).unwrap();
    assert!(md.contains(&format!("{} dropped", failed_groups.len())), "{md}");
}

#[test]
fn sensitivity_counts_runs_missing_from_the_tables_as_failures() {
    // Only the first of two shards ran: every base row misses half of its runs.
    let dir = run_study("shard", &study("shard", "", SOBOL), &["--shard", "1/2"]);
    assert!(!dir.join("sensitivity.parquet").exists(), "a shard alone is not analysed");
    let doc = json_of(&dir, &["--bootstrap", "0"]);
    let part = &doc["parts"][0];
    assert_eq!(part["missing"].as_u64(), Some(64));
    for r in doc["rows"].as_array().unwrap() {
        assert_eq!((r["n_used"].as_u64(), r["n_dropped"].as_u64()), (Some(0), Some(32)));
        assert!(r["S1"].is_null() && r["note"].is_string(), "{r}");
    }
}

#[test]
fn sensitivity_of_a_morris_study() {
    let sample = "[sample]\nmethod = \"morris\"\ntrajectories = 12\nseed = 4";
    let dir = run_study("morris", &study("tiny-morris", "", sample), &[]);
    let doc = json_of(&dir, &[]);
    assert_eq!(doc["parts"][0]["method"], "morris");
    assert_eq!(doc["parts"][0]["runs"].as_u64(), Some(12 * 3));
    for r in doc["rows"].as_array().unwrap() {
        assert!(r["mu_star"].as_f64().unwrap() >= 0.0, "{r}");
        assert!(r["S1"].is_null());
    }
    assert_eq!(doc["ranking"][0]["by"], "mu_star");
    assert!(dir.join("sensitivity-efficiency.svg").exists());
}

#[test]
fn sensitivity_needs_exactly_one_of_dir_or_check() {
    let none = hdw(&["sensitivity"]);
    assert!(!none.status.success());
    let both = hdw(&["sensitivity", "out/x", "--check", "ishigami"]);
    assert!(!both.status.success());
    assert!(String::from_utf8_lossy(&both.stderr).contains("cannot be used with"));
    let not_a_study = scratch("empty");
    let out = hdw(&["sensitivity", not_a_study.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("study.json"));
    let help = ok(&hdw(&["sensitivity", "--help"]));
    assert!(help.trim_end().ends_with("--format json"), "help ends with the examples");
}
