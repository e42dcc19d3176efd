//! End-to-end tests of `hdw simulate`: outputs on the seed case, and one clear error line
//! for each kind of bad input.

use crate::common::*;

#[test]
fn seed_case_writes_trace_metrics_and_plot() {
    let dir = scratch("seed");
    let out = hdw(&["simulate", "--t-end", "0.06", "--out", dir.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table = hd_io::read_table(&dir.join("trace.parquet")).unwrap();
    let expected: Vec<String> =
        hd_model::TRACE_COLUMNS.iter().map(|c| c.name.to_string()).collect();
    assert_eq!(table.names, expected);
    assert!(table.height > 100);
    let metrics: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    assert!(metrics["metrics"]["thz_amp"].as_f64().unwrap() > 0.0);
    assert!(metrics["metrics"]["rise_time"].is_null(), "undefined metrics are null");
    assert!(metrics["solver"]["steps"].as_u64().unwrap() > 0);
    assert_eq!(metrics["parameters"]["sigma0"].as_f64(), Some(1.2e5));
    let svg = std::fs::read_to_string(dir.join("response.svg")).unwrap();
    assert!(svg.starts_with("<svg") || svg.contains("<svg"));
}

#[test]
fn unknown_parameter_in_set_is_named_with_a_suggestion() {
    let dir = scratch("unknown-set");
    let out = hdw(&["simulate", "--set", "sigma00=1", "--out", dir.to_str().unwrap()]);
    assert_one_line_error(&out, &["sigma00", "sigma0"]);
}

#[test]
fn unknown_parameter_in_file_names_file_and_line() {
    let dir = scratch("unknown-file");
    let file = dir.join("p.toml");
    std::fs::write(&file, "c = 6e4\n# comment\nJload = 0.1\n").unwrap();
    let out =
        hdw(&["simulate", "--params", file.to_str().unwrap(), "--out", dir.to_str().unwrap()]);
    assert_one_line_error(&out, &["p.toml:3", "Jload"]);
}

#[test]
fn negative_inertia_is_rejected_with_the_valid_range() {
    let dir = scratch("neg");
    let out = hdw(&["simulate", "--set", "Jz=-0.1", "--out", dir.to_str().unwrap()]);
    assert_one_line_error(&out, &["Jz", "-0.1", "> 0", "kg·m²"]);
}

#[test]
fn nan_value_is_rejected() {
    let dir = scratch("nan");
    let out = hdw(&["simulate", "--set", "c=NaN", "--out", dir.to_str().unwrap()]);
    assert_one_line_error(&out, &["'c'", "NaN", "finite"]);
}

#[test]
fn malformed_toml_names_the_file_and_line() {
    let dir = scratch("toml");
    let file = dir.join("bad.toml");
    std::fs::write(&file, "c = 6e4\nsigma0 = = 3\n").unwrap();
    let out =
        hdw(&["simulate", "--params", file.to_str().unwrap(), "--out", dir.to_str().unwrap()]);
    assert_one_line_error(&out, &["bad.toml:2", "malformed TOML"]);
}

#[test]
fn recorded_input_with_non_increasing_time_names_the_row() {
    let dir = scratch("profile");
    let file = dir.join("u.csv");
    std::fs::write(&file, "t,u\n0.0,0\n0.01,5\n0.01,6\n0.02,0\n").unwrap();
    let out = hdw(&["simulate", "--input", file.to_str().unwrap(), "--out", dir.to_str().unwrap()]);
    assert_one_line_error(&out, &["u.csv", "row 3", "strictly increasing"]);
}

#[test]
fn recorded_input_runs_and_is_interpolated() {
    let dir = scratch("profile-ok");
    let file = dir.join("u.csv");
    std::fs::write(&file, "t,u\n0.0,0\n0.01,12\n0.03,12\n0.04,0\n").unwrap();
    let out = hdw(&[
        "simulate",
        "--input",
        file.to_str().unwrap(),
        "--t-end",
        "0.05",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table = hd_io::read_table(&dir.join("trace.parquet")).unwrap();
    let (t, u) = (table.num("t").unwrap(), table.num("u").unwrap());
    for (&t, &u) in t.iter().zip(u) {
        let expected = if t <= 0.01 {
            1200.0 * t
        } else if t <= 0.03 {
            12.0
        } else if t <= 0.04 {
            12.0 - 1200.0 * (t - 0.03)
        } else {
            0.0
        };
        assert!((u - expected).abs() < 1e-9, "u({t}) = {u}, expected {expected}");
    }
}

#[test]
fn help_ends_with_a_worked_example() {
    let commands: [&[&str]; 12] = [
        &["--help"],
        &["simulate", "--help"],
        &["study", "--help"],
        &["fit", "--help"],
        &["fit", "hysteresis", "--help"],
        &["fit", "friction", "--help"],
        &["synth", "--help"],
        &["synth", "hysteresis", "--help"],
        &["synth", "friction", "--help"],
        &["explore", "--help"],
        &["plot", "--help"],
        &["sensitivity", "--help"],
    ];
    for args in commands {
        let out = hdw(args);
        assert!(out.status.success(), "{args:?}");
        let text = String::from_utf8_lossy(&out.stdout);
        let tail: Vec<&str> = text.trim_end().lines().rev().take(6).collect();
        assert!(
            text.contains("Example") && tail.iter().any(|l| l.trim_start().starts_with("hdw ")),
            "{args:?} help does not end with a worked example:\n{text}"
        );
    }
}

#[test]
fn no_trace_writes_the_metrics_only() {
    let dir = scratch("no-trace");
    let out = dir.join("run");
    hdw_ok(&["simulate", "--no-trace", "--t-end", "0.05", "--out", out.to_str().unwrap()]);
    assert!(out.join("metrics.json").is_file());
    assert!(!out.join("trace.parquet").exists() && !out.join("response.svg").exists());
    let m = json(&out.join("metrics.json"));
    assert!(m["metrics"]["thz_amp"].as_f64().unwrap() > 0.0);
}

#[test]
fn a_long_trace_streams_in_row_groups_and_its_plot_stays_small() {
    // 250 001 samples: four row groups of trace.parquet, and the plot from the envelope.
    let dir = scratch("streamed");
    let out = dir.join("run");
    let o = out.to_str().unwrap();
    hdw_ok(&["simulate", "--t-end", "0.5", "--dt-out", "2e-6", "--out", o]);
    let t = hd_io::read_table(&out.join("trace.parquet")).unwrap();
    assert_eq!(t.height, 250_001);
    let time = t.num("t").unwrap();
    assert!(time.windows(2).all(|w| w[1] > w[0]));
    assert!((time[250_000] - 0.5).abs() < 1e-12);
    let svg = std::fs::metadata(out.join("response.svg")).unwrap().len();
    assert!(svg < 2_000_000, "response.svg {svg} bytes");
}
