//! `hdw fit` on files as rigs write them: comment lines, other separators, extra and
//! mixed-type columns, native units with the opposite sign, speed only as a position.

use crate::common::*;

use std::fmt::Write as _;
use std::path::Path;

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    (names, rows)
}

fn fit_json(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("fit.json")).unwrap()).unwrap()
}

fn value(j: &serde_json::Value, name: &str) -> f64 {
    j["parameters"][name]["value"].as_f64().unwrap()
}

#[test]
fn a_messy_joint_test_file_fits_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let clean = dir.path().join("joint.csv");
    let truth = [
        "Tc=0.2",
        "Ts=0.35",
        "ws=0.02",
        "sigma2=0.05",
        "sigma0=8e4",
        "sigma1=0.5",
        "Tc_neg=0.15",
        "Ts_neg=0.28",
    ];
    let mut args =
        vec!["synth", "friction", "--transient", "--profile", "joint", "--noise", "0.01"];
    for t in &truth {
        args.extend(["--set", t]);
    }
    args.extend(["--out", clean.to_str().unwrap()]);
    hdw_ok(&args);
    let (_, rows) = read_csv(&clean);

    // The rig's file: two comment lines, semicolons, time in ms, the encoder position in
    // mrad (no speed column), torque in mN·m with the opposite sign, and a sample counter
    // that starts as integers and turns to floats far down.
    let mut text = String::from("# joint friction test, axis 3\n# exported by the rig\n");
    text.push_str("counter;time_ms;pos_mrad;torque_mNm;temperature\n");
    let mut position = 0.0;
    for (k, r) in rows.iter().enumerate() {
        if k > 0 {
            let p = &rows[k - 1];
            position += 0.5 * (r[1] + p[1]) * (r[0] - p[0]);
        }
        let counter = if k < 20_000 { format!("{k}") } else { format!("{k}.5") };
        writeln!(
            text,
            "{counter};{};{};{};{}",
            r[0] * 1e3,
            position * 1e3,
            -r[2] * 1e3,
            21 + k % 3
        )
        .unwrap();
    }
    let messy = dir.path().join("rig.txt");
    std::fs::write(&messy, text).unwrap();
    let out = dir.path().join("fit");
    hdw_ok(&[
        "fit",
        "friction",
        "--transient",
        messy.to_str().unwrap(),
        "--transient-columns",
        "time_ms,torque_mNm",
        "--position-column",
        "pos_mrad",
        "--time-scale",
        "1e-3",
        "--position-scale",
        "1e-3",
        "--torque-scale",
        "-1e-3",
        "--asymmetric",
        "--out",
        out.to_str().unwrap(),
    ]);
    let j = fit_json(&out);
    for (name, t) in [("Tc", 0.2), ("Ts", 0.35), ("Tc_neg", 0.15), ("Ts_neg", 0.28), ("ws", 0.02)] {
        let v = value(&j, name);
        println!("{name} = {v} (truth {t})");
        assert!((v / t - 1.0).abs() < 0.05, "{name} = {v}, truth {t}");
    }
    assert!(value(&j, "offset").abs() < 0.01, "{}", j["parameters"]["offset"]);
    for f in [
        "transient.svg",
        "friction-speed.svg",
        "residuals-transient.svg",
        "transient-fitted.parquet",
    ] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn hysteresis_in_native_units() {
    let dir = tempfile::tempdir().unwrap();
    let clean = dir.path().join("h.csv");
    hdw_ok(&[
        "synth",
        "hysteresis",
        "--set",
        "c=6.5e4",
        "--set",
        "B=150",
        "--out",
        clean.to_str().unwrap(),
    ]);
    let (_, rows) = read_csv(&clean);
    // Tab-separated, deflection in arcmin, torque in N·mm, an extra text column.
    let mut text = String::from("t\ttheta_arcmin\ttorque_Nmm\tnote\n");
    let arcmin = std::f64::consts::PI / (180.0 * 60.0);
    for r in &rows {
        writeln!(text, "{}\t{}\t{}\tok", r[0], r[1] / arcmin, r[2] * 1e3).unwrap();
    }
    let f = dir.path().join("rig.tsv");
    std::fs::write(&f, text).unwrap();
    let out = dir.path().join("fit");
    hdw_ok(&[
        "fit",
        "hysteresis",
        f.to_str().unwrap(),
        "--columns",
        "t,theta_arcmin,torque_Nmm",
        "--theta-unit",
        "arcmin",
        "--torque-scale",
        "1e-3",
        "--out",
        out.to_str().unwrap(),
    ]);
    let j = fit_json(&out);
    let c = value(&j, "c");
    let b = value(&j, "mem_B");
    println!("c = {c}, B = {b}");
    assert!((c / 6.5e4 - 1.0).abs() < 0.01 && (b / 150.0 - 1.0).abs() < 0.02, "c {c}, B {b}");
}

#[test]
fn bad_unit_options_are_named() {
    let run = hdw(&["fit", "hysteresis", "x.csv", "--theta-unit", "grad"]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("--theta-unit grad"), "{err}");
    let shipped =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/friction-transient.parquet");
    let run =
        hdw(&["fit", "friction", "--transient", shipped.to_str().unwrap(), "--torque-scale", "0"]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        !run.status.success()
            && err.contains("--torque-scale 0: expected a finite, non-zero factor"),
        "{err}"
    );
}
