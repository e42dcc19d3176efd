//! Nested friction laws stay nested on the repository's recordings: the asymmetric fit
//! (which contains the symmetric law: equal levels on both sides) never scores a higher
//! RMS than the symmetric fit of the same record, and the fit's shortcuts end where the
//! exhaustive fit (`--exhaustive`) does. The synthetic corpus is checked in
//! crates/hd-ident/tests/joint_corpus.rs.

use crate::common::*;

use std::process::Command;

fn data(name: &str) -> String {
    repo_path("data").join(name).to_str().unwrap().to_string()
}

/// RMS [N·m] of `hdw fit friction --transient <args>` with `--asymmetric` or not, and the
/// offset in both (so that the two laws differ only in the negative side's levels), with
/// or without `--exhaustive`.
fn rms(args: &[&str], asymmetric: bool, exhaustive: bool) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fit");
    let mut all: Vec<&str> = vec!["fit", "friction", "--transient"];
    all.extend(args);
    all.push("--offset");
    if asymmetric {
        all.push("--asymmetric");
    }
    if exhaustive {
        all.push("--exhaustive");
    }
    all.extend(["--out", out.to_str().unwrap()]);
    let run = Command::new(env!("CARGO_BIN_EXE_hdw")).args(&all).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    j["transient"]["rms"].as_f64().or_else(|| j["rms"].as_f64()).expect("an rms in fit.json")
}

#[test]
fn the_asymmetric_fit_never_scores_worse_than_the_symmetric_one_and_shortcuts_change_nothing() {
    let tribometer = tribometer_transient_args();
    let transient = data("friction-transient.parquet");
    let records: [(&str, Vec<&str>); 2] = [
        ("tribometer (real)", tribometer.iter().map(String::as_str).collect()),
        ("friction-transient.parquet", vec![&transient]),
    ];
    for (name, args) in &records {
        let (sym, asym) = (rms(args, false, false), rms(args, true, false));
        println!("{name}: symmetric RMS {sym:.6e}, asymmetric {asym:.6e}");
        assert!(asym <= sym * (1.0 + 1e-9), "{name}: asymmetric {asym} above symmetric {sym}");
        for (asymmetric, quick) in [(false, sym), (true, asym)] {
            let full = rms(args, asymmetric, true);
            println!(
                "{name}, asymmetric {asymmetric}: exhaustive RMS {full:.9e}, default {quick:.9e}"
            );
            // RMS, so half the relative tolerance of the corpus's RSS (1e-6).
            assert!(
                (quick - full).abs() <= 5e-7 * full,
                "{name}, asymmetric {asymmetric}: the shortcuts changed the optimum: {quick} vs {full}"
            );
        }
    }
}
