//! The data sets shipped in data/ fit as data/README.md says.

use crate::common::*;

use std::process::Command;

fn data(name: &str) -> String {
    repo_path("data").join(name).to_str().unwrap().to_string()
}

/// Run `hdw fit ...` into a fresh folder and return the parsed fit.json.
fn fit(args: &[&str]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fit");
    let mut all: Vec<&str> = vec!["fit"];
    all.extend(args);
    all.extend(["--out", out.to_str().unwrap()]);
    let run = Command::new(env!("CARGO_BIN_EXE_hdw")).args(&all).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap()
}

fn determined(j: &serde_json::Value, name: &str) -> bool {
    j["parameters"][name]["determined"].as_bool().unwrap()
}

#[test]
fn paper_range_leaves_a_and_b_undetermined() {
    let j = fit(&["hysteresis", &data("hysteresis-paper-range.csv")]);
    assert!(!determined(&j, "a") && !determined(&j, "b"));
    assert!(determined(&j, "c") && determined(&j, "mem_A") && determined(&j, "mem_B"));
}

#[test]
fn wide_range_determines_all_five() {
    let j = fit(&["hysteresis", &data("hysteresis-wide-range.parquet")]);
    for (name, truth) in [("a", 1e8), ("b", 2e6), ("c", 5.2e4), ("mem_A", 4e4), ("mem_B", 300.0)] {
        assert!(determined(&j, name), "{name}");
        let v = j["parameters"][name]["value"].as_f64().unwrap();
        assert!((v / truth - 1.0).abs() < 0.02, "{name} = {v}");
    }
}

#[test]
fn friction_files_determine_all_six() {
    let (s, t) = (data("friction-steady.csv"), data("friction-transient.parquet"));
    let j = fit(&["friction", "--steady", &s, "--transient", &t]);
    for name in ["sigma0", "sigma1", "sigma2", "Tc", "Ts", "ws"] {
        assert!(determined(&j, name), "{name}");
    }
}

#[test]
fn real_tribometer_recording_fits_without_preprocessing() {
    // A real measurement (data/README.md): position only, in mm; friction in µN with the
    // opposite sign. The independent least-squares LuGre fit reaches 0.26 N RMS.
    let args = tribometer_transient_args();
    let mut all = vec!["friction", "--transient"];
    all.extend(args.iter().map(String::as_str));
    let j = fit(&all);
    let rms = j["rms"].as_f64().unwrap();
    println!("tribometer: RMS residual {rms:.4} N over {} samples", j["samples"]);
    assert!(rms <= 0.27, "rms {rms}");
    assert_eq!(j["samples"].as_u64().unwrap(), 42_579);
    for name in ["Tc", "sigma0", "ws"] {
        assert!(determined(&j, name), "{name}: {}", j["parameters"][name]);
    }
    let pre = j["data"][0]["preprocessing"].as_array().unwrap();
    assert!(pre.iter().any(|p| p.as_str().unwrap().contains("Savitzky–Golay")), "{pre:?}");
}
