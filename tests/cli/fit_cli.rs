//! `hdw synth` then `hdw fit` end to end: files written, fit.json layout, recovered values.

use crate::common::*;

#[test]
fn hysteresis_synth_then_fit() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("hyst.csv");
    let out = dir.path().join("fit");
    let (d, o) = (data.to_str().unwrap(), out.to_str().unwrap());
    hdw_ok(&[
        "synth",
        "hysteresis",
        "--set",
        "c=6.5e4",
        "--set",
        "A=2.5e4",
        "--set",
        "B=150",
        "--seed",
        "3",
        "--out",
        d,
    ]);
    let run = hdw_ok(&["fit", "hysteresis", d, "--out", o]);
    let table = String::from_utf8_lossy(&run.stdout);
    assert!(
        table.contains("hysteresis fit: 20000 samples") && table.contains("correlation:"),
        "{table}"
    );
    for f in ["fit.json", "fitted.parquet", "loop.svg", "memory.svg", "residuals.svg"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let j = json(&out.join("fit.json"));
    let params = j["parameters"].as_object().unwrap();
    assert_eq!(params.len(), 5);
    for (name, truth) in [("c", 6.5e4), ("mem_A", 2.5e4), ("mem_B", 150.0)] {
        let p = &params[name];
        let v = p["value"].as_f64().unwrap();
        assert!((v / truth - 1.0).abs() < 0.02, "{name} = {v}");
        assert!(p["std_error"].as_f64().unwrap() > 0.0);
        assert_eq!(p["ci95"].as_array().unwrap().len(), 2);
        assert_eq!(p["determined"], true);
    }
    assert_eq!(params["a"]["determined"], false);
    assert!(params["a"]["note"].as_str().unwrap().contains("deflection range"));
    assert!(j["rms"].as_f64().unwrap() > 0.0 && j["r2"].as_f64().unwrap() > 0.999);
    assert!(j["iterations"].as_u64().unwrap() > 0);
    assert_eq!(j["termination"], "Solver converged");
}

#[test]
fn friction_synth_then_fit_both_stages() {
    let dir = tempfile::tempdir().unwrap();
    let steady = dir.path().join("steady.csv");
    let transient = dir.path().join("transient.parquet");
    let out = dir.path().join("fit");
    let (s, t, o) = (steady.to_str().unwrap(), transient.to_str().unwrap(), out.to_str().unwrap());
    let truth = ["--set", "Tc=0.2", "--set", "Ts=0.35", "--set", "ws=0.02", "--set", "sigma2=0.05"];
    let mut a = vec!["synth", "friction"];
    a.extend(truth);
    a.extend(["--out", s]);
    hdw_ok(&a);
    let mut a = vec![
        "synth",
        "friction",
        "--transient",
        "--set",
        "sigma0=8e4",
        "--set",
        "sigma1=0.5",
        "--seed",
        "2",
    ];
    a.extend(truth);
    a.extend(["--out", t]);
    hdw_ok(&a);
    hdw_ok(&["fit", "friction", "--steady", s, "--transient", t, "--out", o]);
    for f in [
        "fit.json",
        "stribeck.svg",
        "residuals-steady.svg",
        "steady-fitted.parquet",
        "transient.svg",
        "residuals-transient.svg",
        "transient-fitted.parquet",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let j = json(&out.join("fit.json"));
    let params = j["parameters"].as_object().unwrap();
    assert_eq!(params.len(), 6);
    for (name, truth, tol) in [
        ("Tc", 0.2, 0.02),
        ("Ts", 0.35, 0.02),
        ("ws", 0.02, 0.05),
        ("sigma0", 8e4, 0.1),
        ("sigma1", 0.5, 0.1),
    ] {
        let v = params[name]["value"].as_f64().unwrap();
        assert!((v / truth - 1.0).abs() < tol, "{name} = {v}");
    }
    assert_eq!(j["stages"].as_array().unwrap().len(), 2);
    assert!(j["termination"].as_str().unwrap().contains("dynamic stage"));
}

#[test]
fn fix_holds_a_parameter_and_renamed_columns_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("renamed.csv");
    // Columns under other names and in another order.
    let mut text = String::from("torque_Nm,time_s,defl_rad\n");
    for k in 0..2000 {
        let t = k as f64 * 2.5e-4;
        let th = 1e-3 * (std::f64::consts::TAU * 20.0 * t).sin();
        text.push_str(&format!("{},{t},{th}\n", 5.2e4 * th));
    }
    std::fs::write(&csv, text).unwrap();
    let out = dir.path().join("fit");
    let (c, o) = (csv.to_str().unwrap(), out.to_str().unwrap());
    hdw_ok(&[
        "fit",
        "hysteresis",
        c,
        "--columns",
        "time_s,defl_rad,torque_Nm",
        "--fix",
        "A=0",
        "--fix",
        "B=300",
        "--fix",
        "a=0",
        "--fix",
        "b=0",
        "--out",
        o,
    ]);
    let j = json(&out.join("fit.json"));
    assert_eq!(j["parameters"]["mem_A"]["fixed"], true);
    assert!((j["parameters"]["c"]["value"].as_f64().unwrap() / 5.2e4 - 1.0).abs() < 1e-9);
    assert_eq!(j["iterations"], 0);
}
