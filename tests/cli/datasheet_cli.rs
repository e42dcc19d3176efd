//! `hdw datasheet` on the worked example of issue #17: files, the catalogue deflection, the
//! realised hysteresis loss, a seed params file the simulator accepts, and clear errors.

use crate::common::*;

#[test]
fn worked_example_writes_the_catalogue_law_and_a_usable_seed_spring() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let o = out.to_str().unwrap();
    let args = datasheet_example(&["--hysteresis-loss", "1", "--out", o]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let run = hdw_ok(&args);
    assert!(String::from_utf8_lossy(&run.stdout).contains("seed spring"));
    for f in ["catalogue.toml", "seed-params.toml", "datasheet.json", "curves.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let j = json(&out.join("datasheet.json"));
    // T2 sits in the middle of the second rounded corner, where the rounded curve runs
    // (K3 − K2)·h/4 ≈ 0.05 N·m above the sharp one: the deflection is 4e-4 smaller.
    let sharp = 29.0 / 6.7e4 + 79.0 / 1.1e5;
    let got = j["rated_deflection"].as_f64().unwrap();
    assert!(got < sharp && (1.0 - got / sharp) < 1e-3, "{got} vs {sharp}");
    let loss = j["hysteresis_loss_arcmin"]["model"].as_f64().unwrap();
    assert!((loss - 1.0).abs() < 1e-3, "{loss}");
    assert!(j["seed_spring"]["rms_error"].as_f64().unwrap() > 0.0);
    let cat = std::fs::read_to_string(out.join("catalogue.toml")).unwrap();
    assert!(cat.contains("cat_K1 = 6.7e4") && cat.contains("ms_k4"), "{cat}");
    let sim = dir.path().join("sim");
    simulate_params_file(&out.join("seed-params.toml"), &sim);
}

#[test]
fn bad_catalogue_values_name_the_flag() {
    // The worked example with T2 below T1.
    let mut args = datasheet_example(&[]);
    *args.last_mut().unwrap() = "20".to_string();
    let out = hdw(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_one_line_error(&out, &["--t2", "expected a torque above T1"]);
    let args = datasheet_example(&["--hysteresis-loss", "30"]);
    let out = hdw(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_one_line_error(&out, &["--hysteresis-loss", "expected at most"]);
}
