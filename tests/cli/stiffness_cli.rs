//! `hdw simulate --stiffness`: every law runs, the chosen law is recorded, a catalogue
//! params file from `hdw datasheet` selects its law, and bad choices fail in one sentence.

use crate::common::*;

#[test]
fn every_stiffness_law_simulates_and_is_recorded() {
    let dir = scratch("stiffness-laws");
    for law in ["memory", "maxwell-slip", "bouc-wen", "catalogue"] {
        let out = dir.join(law);
        let o = out.to_str().unwrap();
        hdw_ok(&["simulate", "--stiffness", law, "--t-end", "0.05", "--out", o]);
        let m = json(&out.join("metrics.json"));
        assert_eq!(m["stiffness"], law);
        let residual = m["metrics"]["energy_residual"].as_f64().unwrap();
        assert!(residual < 1e-8, "{law}: energy residual {residual}");
    }
}

#[test]
fn a_datasheet_params_file_selects_the_catalogue_law() {
    let dir = scratch("stiffness-datasheet");
    let ds = dir.join("ds");
    let args = datasheet_example(&["--hysteresis-loss", "1", "--out", ds.to_str().unwrap()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    hdw_ok(&args);
    let sim = dir.join("sim");
    simulate_params_file(&ds.join("catalogue.toml"), &sim);
    assert_eq!(json(&sim.join("metrics.json"))["stiffness"], "catalogue");
}

#[test]
fn bad_stiffness_choices_fail_in_one_sentence() {
    let dir = scratch("stiffness-bad");
    let o = dir.join("x");
    let o = o.to_str().unwrap();
    let out = hdw(&["simulate", "--variant", "linear", "--stiffness", "bouc-wen", "--out", o]);
    assert_one_line_error(&out, &["stiffness", "full variant"]);
    let out = hdw(&["simulate", "--stiffness", "maxwell-slip", "--set", "ms_n=13", "--out", o]);
    assert_one_line_error(&out, &["ms_n", "[1, 12]"]);
    let out = hdw(&["simulate", "--stiffness", "catalogue", "--set", "cat_loss=0.01", "--out", o]);
    assert_one_line_error(&out, &["cat_loss", "at most"]);
    let out = hdw(&["simulate", "--stiffness", "catalogue", "--set", "cat_T2=10", "--out", o]);
    assert_one_line_error(&out, &["cat_T2", "above T1"]);
}
