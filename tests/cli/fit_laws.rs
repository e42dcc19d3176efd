//! `hdw synth hysteresis --law …` then `hdw fit hysteresis --law all`: the comparison
//! ranks a rate-independent law first on rate-independent loops (residual near the noise,
//! loop energies near the truth) and the memory law first on the shipped memory-law data.

use crate::common::*;
use std::path::Path;

fn synth(dir: &Path, law: &str, noise: &str, name: &str) -> String {
    let path = dir.join(name);
    let p = path.to_str().unwrap().to_string();
    let args = [
        "synth",
        "hysteresis",
        "--law",
        law,
        "--schedule",
        "quasi-static",
        "--noise",
        noise,
        "--seed",
        "11",
        "--out",
        &p,
    ];
    hdw_ok(&args);
    p
}

fn noise_of(stderr: &[u8]) -> f64 {
    let text = String::from_utf8_lossy(stderr);
    let tail = text.split("RMS torque = ").nth(1).expect("noise in the description");
    tail.split_whitespace().next().unwrap().parse().unwrap()
}

/// Fit every law; return comparison.json and the noise the synthesis reported.
fn compare(dir: &Path, law: &str) -> (serde_json::Value, f64) {
    let data = dir.join(format!("{law}.csv"));
    let d = data.to_str().unwrap();
    let made = hdw_ok(&[
        "synth",
        "hysteresis",
        "--law",
        law,
        "--schedule",
        "quasi-static",
        "--seed",
        "11",
        "--out",
        d,
    ]);
    let out = dir.join(format!("fit-{law}"));
    hdw_ok(&["fit", "hysteresis", d, "--law", "all", "--out", out.to_str().unwrap()]);
    for sub in ["memory", "maxwell-slip", "bouc-wen"] {
        for f in ["fit.json", "fitted.parquet", "loop.svg", "memory.svg", "residuals.svg"] {
            assert!(out.join(sub).join(f).is_file(), "{sub}/{f}");
        }
    }
    assert!(out.join("comparison.md").is_file());
    (json(&out.join("comparison.json")), noise_of(&made.stderr))
}

#[test]
fn maxwell_slip_loop_ranks_a_rate_independent_law_first_with_the_true_loop_energy() {
    let dir = tempfile::tempdir().unwrap();
    let (cmp, sd) = compare(dir.path(), "maxwell-slip");
    let best = &cmp[0];
    assert_ne!(best["law"], "memory", "{cmp}");
    assert!(best["rms"].as_f64().unwrap() < 1.3 * sd, "{cmp} noise {sd}");
    for key in ["law", "rms", "aic", "bic", "parameters"] {
        assert!(!best[key].is_null(), "{key}");
    }
    // Loop energies against the clean record's (the same law without noise).
    let clean = synth(dir.path(), "maxwell-slip", "0", "clean.csv");
    let out = dir.path().join("fit-clean");
    hdw_ok(&["fit", "hysteresis", &clean, "--law", "memory", "--out", out.to_str().unwrap()]);
    let truth = json(&out.join("fit.json"))["loop_energy"].clone();
    let law = best["law"].as_str().unwrap();
    let fitted = json(&dir.path().join("fit-maxwell-slip").join(law).join("fit.json"));
    let blocks = fitted["loop_energy"].as_array().unwrap();
    assert_eq!(blocks.len(), 6, "{blocks:?}");
    for (f, t) in blocks.iter().zip(truth.as_array().unwrap()) {
        let m = f["model_energy_per_cycle"].as_f64().unwrap();
        let e = t["measured_energy_per_cycle"].as_f64().unwrap();
        assert!((m / e - 1.0).abs() < 0.05, "{f} vs {t}");
    }
    // fitted.parquet: the input's columns and the fitted torque, row for row.
    let t = hd_io::read_table(&dir.path().join("fit-maxwell-slip/maxwell-slip/fitted.parquet"))
        .unwrap();
    let n = t.num("t").unwrap().len();
    assert_eq!(n, 33_001);
    assert!(t.num("theta").is_some() && t.num("torque").is_some() && t.num("fitted").is_some());
}

#[test]
fn bouc_wen_loop_ranks_a_rate_independent_law_first() {
    let dir = tempfile::tempdir().unwrap();
    let (cmp, sd) = compare(dir.path(), "bouc-wen");
    assert_ne!(cmp[0]["law"], "memory", "{cmp}");
    assert!(cmp[0]["rms"].as_f64().unwrap() < 1.3 * sd, "{cmp} noise {sd}");
}

#[test]
fn shipped_memory_law_data_rank_the_memory_law_first() {
    let dir = tempfile::tempdir().unwrap();
    let data = repo_path("data/hysteresis-paper-range.csv");
    let out = dir.path().join("cmp");
    hdw_ok(&[
        "fit",
        "hysteresis",
        data.to_str().unwrap(),
        "--law",
        "all",
        "--out",
        out.to_str().unwrap(),
    ]);
    let cmp = json(&out.join("comparison.json"));
    assert_eq!(cmp[0]["law"], "memory", "{cmp}");
    assert!(cmp[1]["delta_bic"].as_f64().unwrap() > 10.0, "{cmp}");
}

#[test]
fn unknown_law_is_one_clear_error() {
    let data = repo_path("data/hysteresis-paper-range.csv");
    let out = hdw(&["fit", "hysteresis", data.to_str().unwrap(), "--law", "preisach"]);
    assert_one_line_error(&out, &["--law", "preisach", "memory, maxwell-slip, bouc-wen or all"]);
}
