//! Helpers shared by every end-to-end test of the `hdw` binary.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the `hdw` binary built for this test run with `args`.
pub fn hdw(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hdw")).args(args).output().expect("run hdw")
}

/// Runs `hdw` and fails the test, with its stderr, unless it succeeds.
pub fn hdw_ok(args: &[&str]) -> Output {
    let out = hdw(args);
    assert!(out.status.success(), "hdw {args:?} failed:\n{}", String::from_utf8_lossy(&out.stderr));
    out
}

/// Asserts `out` succeeded and returns its stdout.
pub fn ok(out: &Output) -> String {
    assert!(out.status.success(), "hdw failed:\n{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A fresh, empty scratch folder unique to this process and `name`.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hdw-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path under the repository root (`data/...`, `studies/...`).
pub fn repo_path(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

/// The options after `--transient` that read the shipped tribometer recording
/// (data/README.md): position in mm, friction in µN with the opposite sign.
pub fn tribometer_transient_args() -> Vec<String> {
    let path = repo_path("data/tribometer-reciprocating.txt");
    [
        path.to_str().unwrap(),
        "--transient-columns",
        "Time [s],Friction [uN]",
        "--position-column",
        "Position [mm]",
        "--position-scale",
        "1e-3",
        "--torque-scale",
        "-1e-6",
    ]
    .map(String::from)
    .to_vec()
}

/// Parses a JSON file.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The run fails with a non-zero exit and a single stderr line containing every needle.
pub fn assert_one_line_error(out: &Output, needles: &[&str]) {
    assert!(!out.status.success(), "expected failure, got success");
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one error line, got:\n{err}");
    for n in needles {
        assert!(lines[0].contains(n), "error line {:?} lacks {n:?}", lines[0]);
    }
}

/// A three-run study whose middle run fails (an inertia of 1e-12 kg·m² exhausts the step
/// budget), for the tests of failed rows.
pub const FAILING_STUDY: &str = r#"
name = "failing"
[base]
variant = "damped"
t_end = 0.02
[solver]
max_steps = 20000
[[axis]]
name = "Jz"
values = [0.024, 1e-12, 0.05]
"#;

/// `hdw datasheet` with the worked example of issue #17 (data/catalogue/README.md); append
/// the remaining flags.
pub fn datasheet_example(more: &[&str]) -> Vec<String> {
    let base = [
        "datasheet",
        "--k1",
        "6.7e4",
        "--k2",
        "1.1e5",
        "--k3",
        "1.2e5",
        "--t1",
        "29",
        "--t2",
        "108",
    ];
    base.iter().chain(more).map(|s| s.to_string()).collect()
}

/// `hdw simulate --params PARAMS --t-end 0.02 --out OUT`, which must succeed.
pub fn simulate_params_file(params: &Path, out: &Path) -> Output {
    hdw_ok(&[
        "simulate",
        "--params",
        params.to_str().unwrap(),
        "--t-end",
        "0.02",
        "--out",
        out.to_str().unwrap(),
    ])
}

/// Run `hdw fit drive --config cfg --out out`.
pub fn fit_drive(cfg: &std::path::Path, out: &std::path::Path) -> std::process::Output {
    hdw(&["fit", "drive", "--config", cfg.to_str().unwrap(), "--out", out.to_str().unwrap()])
}

/// Run `hdw simulate` on the params.toml a fit wrote to `out`, into `sim` (it must run).
pub fn simulates(out: &std::path::Path, sim: &std::path::Path) {
    let params = out.join("params.toml");
    let args = ["simulate", "--params", params.to_str().unwrap(), "--t-end", "0.05", "--out"];
    let mut args = args.to_vec();
    args.push(sim.to_str().unwrap());
    hdw_ok(&args);
}

/// `hdw synth drive --loop-kp 30 ARGS --out OUT` (ARGS split at whitespace): a closed-loop
/// record of the seed drive at the docs' position gain; fails the test unless it succeeds.
pub fn synth_loop(args: &str, out: &Path) -> Output {
    let mut all = vec!["synth", "drive", "--loop-kp", "30"];
    all.extend(args.split_whitespace());
    all.extend(["--out", out.to_str().unwrap()]);
    hdw_ok(&all)
}
