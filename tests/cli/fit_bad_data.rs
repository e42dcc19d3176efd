//! Bad data given to `hdw fit` is an error on stderr, with a non-zero exit, that says
//! what is wrong and where.

use crate::common::*;

use std::path::Path;

/// Run hdw, expect failure, return stderr.
fn fails(args: &[&str]) -> String {
    let out = hdw(args);
    assert!(!out.status.success(), "hdw {args:?} should fail");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A small valid hysteresis CSV body with `n` rows, then `edit` applied to the lines.
fn hysteresis_csv(dir: &Path, name: &str, n: usize, edit: impl Fn(&mut Vec<String>)) -> String {
    let mut lines = vec!["t,theta,torque".to_string()];
    for k in 0..n {
        let t = k as f64 * 1e-3;
        let th = 1e-3 * (t * 30.0).sin();
        lines.push(format!("{t},{th},{}", 5e4 * th));
    }
    edit(&mut lines);
    let path = dir.join(name);
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn missing_column() {
    let dir = tempfile::tempdir().unwrap();
    let f = hysteresis_csv(dir.path(), "m.csv", 100, |l| l[0] = "t,deflection,torque".into());
    let err = fails(&["fit", "hysteresis", &f, "--out", dir.path().join("o").to_str().unwrap()]);
    assert!(err.contains("missing column 'theta'") && err.contains("deflection"), "{err}");
}

#[test]
fn nan_and_infinite_values_with_their_row() {
    let dir = tempfile::tempdir().unwrap();
    let f = hysteresis_csv(dir.path(), "nan.csv", 100, |l| l[8] = "0.007,NaN,1.0".into());
    let err = fails(&["fit", "hysteresis", &f, "--out", dir.path().join("o").to_str().unwrap()]);
    assert!(err.contains("column 'theta', row 8") && err.contains("NaN"), "{err}");
    let f = hysteresis_csv(dir.path(), "inf.csv", 100, |l| l[3] = "0.002,0.0,inf".into());
    let err = fails(&["fit", "hysteresis", &f, "--out", dir.path().join("o").to_str().unwrap()]);
    assert!(err.contains("column 'torque', row 3") && err.contains("inf"), "{err}");
}

#[test]
fn non_increasing_time_with_its_row() {
    let dir = tempfile::tempdir().unwrap();
    let f = hysteresis_csv(dir.path(), "t.csv", 100, |l| l[51] = "0.0485,0.0,0.0".into());
    let err = fails(&["fit", "hysteresis", &f, "--out", dir.path().join("o").to_str().unwrap()]);
    assert!(err.contains("row 51") && err.contains("time must increase strictly"), "{err}");
    // The transient friction file is checked the same way.
    let tr = dir.path().join("tr.csv");
    std::fs::write(&tr, "t,omega,torque\n0,0,0\n0.001,0.1,0.1\n0.001,0.2,0.2\n").unwrap();
    let err = fails(&[
        "fit",
        "friction",
        "--transient",
        tr.to_str().unwrap(),
        "--fix",
        "Tc=0.1",
        "--fix",
        "Ts=0.2",
        "--fix",
        "ws=0.01",
        "--out",
        dir.path().join("o").to_str().unwrap(),
    ]);
    assert!(err.contains("row 3") && err.contains("time"), "{err}");
}

#[test]
fn too_few_samples_for_the_free_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let f = hysteresis_csv(dir.path(), "few.csv", 7, |_| {});
    let err = fails(&["fit", "hysteresis", &f, "--out", dir.path().join("o").to_str().unwrap()]);
    assert!(err.contains("7 samples are too few to fit 5 free parameter(s)"), "{err}");
    assert!(err.contains("need at least 8"), "{err}");
}

#[test]
fn unknown_fix_name_and_missing_files() {
    let dir = tempfile::tempdir().unwrap();
    let f = hysteresis_csv(dir.path(), "ok.csv", 100, |_| {});
    let err = fails(&[
        "fit",
        "hysteresis",
        &f,
        "--fix",
        "BB=300",
        "--out",
        dir.path().join("o").to_str().unwrap(),
    ]);
    assert!(err.contains("unknown parameter 'BB'") && err.contains("did you mean"), "{err}");
    let err = fails(&["fit", "hysteresis", &f, "--fix", "sigma0=1e5"]);
    assert!(err.contains("not a parameter of the hysteresis fit"), "{err}");
    let err = fails(&["fit", "friction"]);
    assert!(err.contains("no friction data"), "{err}");
    let err = fails(&["fit", "hysteresis", dir.path().join("absent.csv").to_str().unwrap()]);
    assert!(err.contains("absent.csv"), "{err}");
}
