//! Fault injection (issue #39): interrupts at a random moment, failing runs after good
//! ones, and outputs too large to write. Whatever happens, a folder holds whole results of
//! one run each (or nothing new), no temporaries, and a study stays resumable.

use crate::common::{hdw, hdw_ok, scratch};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Every file under `dir` (recursively), as paths relative to it.
fn files(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap().display().to_string());
            }
        }
    }
    out.sort();
    out
}

/// A delay in `[lo, hi)` ms that differs from run to run (the clock's nanoseconds).
fn random_ms(lo: u64, hi: u64) -> Duration {
    let nanos = SystemTime::now().duration_since(UNIX_EPOCH).unwrap().subsec_nanos() as u64;
    Duration::from_millis(lo + nanos % (hi - lo))
}

/// Start `hdw args`, wait `after`, send SIGINT; returns the exit code and stderr.
fn interrupt(args: &[&str], after: Duration) -> (Option<i32>, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_hdw"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let _ = Command::new("kill").args(["-INT", &child.id().to_string()]).status();
    let out = child.wait_with_output().unwrap();
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

fn snapshot(dir: &Path) -> Vec<(String, Vec<u8>)> {
    files(dir).into_iter().map(|f| (f.clone(), std::fs::read(dir.join(&f)).unwrap())).collect()
}

#[test]
fn failing_and_interrupted_runs_leave_the_earlier_results_whole() {
    let dir = scratch("fault-simulate");
    let out = dir.join("run");
    hdw_ok(&["simulate", "--t-end", "0.05", "--out", s(&out)]);
    let good = snapshot(&out);
    assert_eq!(
        good.iter().map(|(f, _)| f.as_str()).collect::<Vec<_>>(),
        ["metrics.json", "response.svg", "trace.parquet"]
    );
    // Fails inside the solve (after the trace began): nothing of it may stay.
    let bad =
        hdw(&["simulate", "--stiffness", "maxwell-slip", "--set", "ms_n=2.5", "--out", s(&out)]);
    assert!(!bad.status.success());
    assert_eq!(snapshot(&out), good, "a failed run changed the folder");
    // Interrupted at a random moment of a long run.
    let (code, err) = interrupt(
        &[
            "simulate",
            "--t-end",
            "1e5",
            "--dt-out",
            "1e-3",
            "--max-output-values",
            "0",
            "--out",
            s(&out),
        ],
        random_ms(300, 1500),
    );
    assert_eq!(code, Some(130), "{err}");
    assert!(err.contains("interrupted (SIGINT)"), "{err}");
    assert_eq!(snapshot(&out), good, "an interrupted run changed the folder");
}

#[test]
fn a_failed_or_interrupted_run_leaves_no_folder_it_created() {
    let dir = scratch("fault-new-folder");
    // A folder two levels deep that did not exist: both levels go with the failed run.
    let out = dir.join("new").join("run");
    let bad =
        hdw(&["simulate", "--stiffness", "maxwell-slip", "--set", "ms_n=2.5", "--out", s(&out)]);
    assert!(!bad.status.success());
    assert!(!dir.join("new").exists(), "a failed run left the folders it created");
    let (code, err) = interrupt(
        &["simulate", "--t-end", "1e5", "--max-output-values", "0", "--out", s(&out)],
        random_ms(300, 1200),
    );
    assert_eq!(code, Some(130), "{err}");
    assert!(!dir.join("new").exists(), "an interrupted run left the folders it created");
    // A folder that existed before stays, empty or not.
    std::fs::create_dir_all(&out).unwrap();
    let bad = hdw(&["simulate", "--set", "c=1e308", "--out", s(&out)]);
    assert!(!bad.status.success());
    assert!(out.is_dir(), "a failed run removed a folder it did not create");
}

#[test]
fn runs_that_cannot_succeed_are_refused_before_they_start() {
    let dir = scratch("fault-upfront");
    let out = dir.join("run");
    let cases: [(&[&str], &str); 5] = [
        (&["--set", "c=1e308"], "parameter c = 1e308: expected values whose equations stay finite"),
        (&["--set", "Tc=1e308"], "parameter Tc = 1e308"),
        (&["--t-end", "1e308"], "max_steps"),
        (&["--voltage", "1e308"], "finite [V, V/s]"),
        (&["--input", "chirp", "--freq", "1e9"], "max_steps"),
    ];
    for (args, says) in cases {
        let mut all = vec!["simulate"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--out", s(&out)]);
        let r = hdw(&all);
        crate::common::assert_one_line_error(&r, &[says]);
        assert!(!out.exists(), "{args:?} created its folder");
    }
}

#[test]
fn a_metrics_only_run_removes_the_older_trace() {
    let dir = scratch("fault-no-trace");
    let out = dir.join("run");
    hdw_ok(&["simulate", "--t-end", "0.05", "--out", s(&out)]);
    hdw_ok(&["simulate", "--t-end", "0.05", "--no-trace", "--out", s(&out)]);
    assert_eq!(files(&out), ["metrics.json"]);
}

const LONG_STUDY: &str = r#"
name = "long"
[base]
variant = "damped"
t_end = 0.05
[traces]
keep = true
decimate = 4
[[axis]]
name = "Kbar"
logspace = { start = 1e5, stop = 1e7, num = 60 }
"#;

#[test]
fn an_interrupted_study_leaves_no_temporaries_and_resumes_to_the_full_table() {
    let dir = scratch("fault-study");
    let file = dir.join("long.toml");
    std::fs::write(&file, LONG_STUDY).unwrap();
    let out = dir.join("out");
    let args = ["study", s(&file), "--out", s(&out), "--threads", "1", "--no-report"];
    let (code, err) = interrupt(&args, random_ms(200, 1200));
    if code == Some(0) {
        // Finished before the signal: nothing to check but the table.
        assert!(out.join("runs.parquet").exists());
        return;
    }
    assert_eq!(code, Some(130), "{err}");
    let left = files(&out);
    assert!(
        left.iter().all(|f| !f.contains(".tmp-") && !f.ends_with(".lock")),
        "temporaries or a lock left: {left:?}"
    );
    let resumed = hdw_ok(&[&args[..], &["--resume"]].concat());
    let text = String::from_utf8_lossy(&resumed.stderr);
    assert!(text.contains("60 rows in"), "{text}");
    let left = files(&out);
    assert!(left.iter().all(|f| !f.contains(".tmp-")), "{left:?}");
    assert!(left.contains(&"traces.parquet".to_string()), "{left:?}");
}

#[test]
fn outputs_too_large_are_refused_before_anything_is_written() {
    let dir = scratch("fault-size");
    let out = dir.join("big");
    let r = hdw(&["simulate", "--t-end", "1e5", "--dt-out", "1e-6", "--out", s(&out)]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success() && err.contains("--max-output-values"), "{err}");
    assert!(!out.exists(), "a refused run created its folder");
    // The same limit, made small, for a study's kept traces.
    let file = dir.join("long.toml");
    std::fs::write(&file, LONG_STUDY).unwrap();
    let r = hdw(&["study", s(&file), "--out", s(&out), "--max-output-values", "1000"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success() && err.contains("more than 1000 values"), "{err}");
    assert!(!out.exists());
}

#[test]
fn outputs_honour_the_umask() {
    let dir = scratch("fault-umask");
    let out = dir.join("run");
    let cmd = format!(
        "umask 027; exec '{}' simulate --t-end 0.02 --out '{}'",
        env!("CARGO_BIN_EXE_hdw"),
        s(&out)
    );
    assert!(Command::new("sh").args(["-c", &cmd]).status().unwrap().success());
    use std::os::unix::fs::PermissionsExt;
    for f in ["metrics.json", "response.svg", "trace.parquet"] {
        let mode = std::fs::metadata(out.join(f)).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640, "{f}: mode {mode:o}");
    }
}

#[test]
fn a_second_study_on_a_folder_is_refused_and_a_stale_lock_taken_over() {
    let dir = scratch("fault-lock");
    let file = dir.join("small.toml");
    std::fs::write(
        &file,
        "name = \"small\"\n[base]\nt_end = 0.01\n[[axis]]\nname = \"voltage\"\nvalues = [6, 12]\n",
    )
    .unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let lock = out.join(".hdw-study.lock");
    // Held by a live process (this test).
    std::fs::write(&lock, format!("pid = {}\nhost = \"{}\"\n", std::process::id(), host()))
        .unwrap();
    let r = hdw(&["study", s(&file), "--out", s(&out), "--no-report"]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!r.status.success(), "{err}");
    assert!(
        err.contains(&format!("pid {}", std::process::id())) && err.contains("running already"),
        "{err}"
    );
    // Left by a process that is gone.
    std::fs::write(&lock, format!("pid = 4294967294\nhost = \"{}\"\n", host())).unwrap();
    hdw_ok(&["study", s(&file), "--out", s(&out), "--no-report"]);
    assert!(!lock.exists(), "the lock outlived the study");
}

fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap().trim().to_string()
}
