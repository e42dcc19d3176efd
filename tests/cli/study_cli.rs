//! End-to-end tests of `hdw study`: schema, failed rows, kill-and-resume, shards.

use crate::common::*;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn write_study(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("study.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn ids(table: &hd_io::Table) -> Vec<String> {
    table.text("run_id").unwrap().iter().map(|s| s.clone().unwrap()).collect()
}

const SMALL: &str = r#"
name = "small"
[base]
variant = "damped"
t_end = 0.04
[metrics]
keep = ["thz_amp", "thz_ripple", "efficiency"]
[[axis]]
name = "Kbar"
values = [2e5, 7.8e5]
[[axis]]
name = "voltage"
values = [12, 24, 36]
"#;

#[test]
fn a_small_study_has_the_documented_schema_and_one_row_per_run() {
    let dir = scratch("schema");
    let file = write_study(&dir, SMALL);
    let out_dir = dir.join("out");
    ok(&hdw(&["study", file.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]));
    let t = hd_io::read_table(&out_dir.join("runs.parquet")).unwrap();
    assert_eq!(t.height, 6);
    let mut expected: Vec<String> =
        ["run_id", "run_index", "part", "variant", "stiffness", "status", "error"]
            .map(String::from)
            .to_vec();
    expected.extend(hd_model::registry::REGISTRY.iter().map(|p| p.name.to_string()));
    expected.extend(
        [
            "voltage",
            "freq",
            "thz_amp",
            "thz_ripple",
            "efficiency",
            "method",
            "steps",
            "rejected_steps",
            "rhs_evals",
            "jac_evals",
            "wall_time",
        ]
        .map(String::from),
    );
    assert_eq!(t.names, expected);
    let unique: BTreeSet<String> = ids(&t).into_iter().collect();
    assert_eq!(unique.len(), 6);
    assert!(t.text("status").unwrap().iter().all(|s| s.as_deref() == Some("ok")));
    let kbar = t.num("Kbar").unwrap();
    let volt = t.num("voltage").unwrap();
    assert_eq!((kbar[0], volt[0], kbar[5], volt[5]), (2e5, 12.0, 7.8e5, 36.0));
    // Linear physics of the damped variant: amplitude proportional to voltage.
    let amp = t.num("thz_amp").unwrap();
    assert!((amp[2] / amp[0] - 3.0).abs() < 1e-3, "{amp:?}");
    assert!(out_dir.join("study.json").exists() && out_dir.join("report.md").exists());
    assert!(!out_dir.join("parts").exists(), "part files are merged and removed");
}

#[test]
fn a_failing_point_is_a_failed_row_and_the_rest_succeed() {
    let dir = scratch("failing");
    let text = FAILING_STUDY;
    let file = write_study(&dir, text);
    let out_dir = dir.join("out");
    ok(&hdw(&["study", file.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]));
    let t = hd_io::read_table(&out_dir.join("runs.parquet")).unwrap();
    let status: Vec<String> =
        t.text("status").unwrap().iter().map(|s| s.clone().unwrap()).collect();
    assert_eq!(status, ["ok", "failed", "ok"]);
    let err = t.text("error").unwrap()[1].clone().unwrap();
    assert!(err.contains("steps"), "{err}");
    assert!(t.num("thz_amp").unwrap()[1].is_nan(), "a failed run has no metrics");
    assert!(t.num("thz_amp").unwrap()[0] > 0.0);
}

#[test]
fn a_killed_sweep_resumes_with_every_run_exactly_once() {
    let dir = scratch("resume");
    let text = r#"
name = "resume"
[base]
variant = "full"
t_end = 0.06
[[axis]]
name = "c"
logspace = { start = 3e4, stop = 9e4, num = 40 }
[[axis]]
name = "voltage"
linspace = { start = 6, stop = 30, num = 15 }
"#;
    let file = write_study(&dir, text);
    let out_dir = dir.join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_hdw"))
        .args([
            "study",
            file.to_str().unwrap(),
            "--out",
            out_dir.to_str().unwrap(),
            "--threads",
            "2",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it once the first part has been committed (or give up waiting after a while).
    let start = Instant::now();
    let parts = out_dir.join("parts");
    loop {
        let committed = std::fs::read_dir(&parts)
            .map(|d| {
                d.filter_map(Result::ok)
                    .any(|e| e.file_name().to_string_lossy().starts_with("runs-"))
            })
            .unwrap_or(false);
        if committed || start.elapsed() > Duration::from_secs(120) {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let killed_early = child.try_wait().unwrap().is_none();
    child.kill().ok();
    child.wait().unwrap();
    assert!(killed_early, "the sweep finished before it could be interrupted; make it longer");
    assert!(!out_dir.join("runs.parquet").exists(), "the sweep was interrupted before the end");
    // Without --resume the folder is refused, so nothing is overwritten.
    let refused = hdw(&["study", file.to_str().unwrap(), "--out", out_dir.to_str().unwrap()]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--resume"));
    ok(&hdw(&[
        "study",
        file.to_str().unwrap(),
        "--out",
        out_dir.to_str().unwrap(),
        "--resume",
        "--no-report",
    ]));
    let t = hd_io::read_table(&out_dir.join("runs.parquet")).unwrap();
    assert_eq!(t.height, 600);
    let unique: BTreeSet<String> = ids(&t).into_iter().collect();
    assert_eq!(unique.len(), 600, "no run duplicated");
    let idx: BTreeSet<u64> = t.num("run_index").unwrap().iter().map(|x| *x as u64).collect();
    assert_eq!(idx, (0..600).collect::<BTreeSet<u64>>(), "no run missing");
}

#[test]
fn two_shards_together_equal_the_whole() {
    let dir = scratch("shards");
    let file = write_study(&dir, SMALL);
    let whole = dir.join("whole");
    let sharded = dir.join("sharded");
    ok(&hdw(&["study", file.to_str().unwrap(), "--out", whole.to_str().unwrap(), "--no-report"]));
    for k in ["1/2", "2/2"] {
        ok(&hdw(&[
            "study",
            file.to_str().unwrap(),
            "--out",
            sharded.to_str().unwrap(),
            "--shard",
            k,
        ]));
    }
    let w = hd_io::read_table(&whole.join("runs.parquet")).unwrap();
    let s1 = hd_io::read_table(&sharded.join("runs-shard-1-of-2.parquet")).unwrap();
    let s2 = hd_io::read_table(&sharded.join("runs-shard-2-of-2.parquet")).unwrap();
    let (a, b): (BTreeSet<String>, BTreeSet<String>) =
        (ids(&s1).into_iter().collect(), ids(&s2).into_iter().collect());
    assert!(a.is_disjoint(&b));
    let union: BTreeSet<String> = a.union(&b).cloned().collect();
    assert_eq!(union, ids(&w).into_iter().collect::<BTreeSet<String>>());
    // Same run id, same result.
    for shard in [&s1, &s2] {
        for (k, id) in ids(shard).iter().enumerate() {
            let j = ids(&w).iter().position(|x| x == id).unwrap();
            assert_eq!(shard.num("thz_amp").unwrap()[k], w.num("thz_amp").unwrap()[j]);
        }
    }
}

#[test]
fn study_file_errors_name_file_line_and_key() {
    let dir = scratch("errors");
    let cases = [
        (
            "name = \"x\"\n[base]\nvariant = \"full\"\nt_ned = 0.1\n",
            vec!["study.toml:4", "t_ned", "t_end"],
        ),
        (
            "name = \"x\"\n\n[[axis]]\nname = \"sigma00\"\nvalues = [1, 2]\n",
            vec!["study.toml:4", "sigma00", "did you mean 'sigma0'"],
        ),
        (
            "name = \"x\"\n[[axis]]\nname = \"c\"\nvalues = []\n",
            vec!["study.toml:3", "c", "empty axis"],
        ),
        (
            "name = \"x\"\n[[axis]]\nname = \"Jz\"\nvalues = [0.1, -2]\n",
            vec!["study.toml:3", "Jz", "-2", "> 0"],
        ),
    ];
    for (text, needles) in cases {
        let file = write_study(&dir, text);
        let out = hdw(&["study", file.to_str().unwrap(), "--out", dir.join("o").to_str().unwrap()]);
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        for n in needles {
            assert!(err.contains(n), "error {err:?} lacks {n:?}");
        }
    }
}

/// Without `--threads`, a study runs on RAYON_NUM_THREADS threads where the environment sets
/// it (a job script's, a user sharing the machine), as its first line says.
#[test]
fn a_study_without_threads_follows_rayon_num_threads() {
    let dir = scratch("rayon-threads");
    let file = write_study(&dir, SMALL);
    let out_dir = dir.join("out");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hdw"))
        .args(["study", file.to_str().unwrap(), "--out", out_dir.to_str().unwrap()])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .unwrap();
    ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(" on 1 threads"), "{err}");
}
