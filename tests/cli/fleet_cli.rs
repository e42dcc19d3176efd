//! `hdw fleet` and `hdw synth fleet` end to end: failed logs as rows, the worn unit found,
//! resume after an interrupt, shards merged into the one-run table, one-line refusals.

use crate::common::{assert_one_line_error, hdw, hdw_ok, scratch};
use hd_io::table::{ColumnData, Table};
use std::path::Path;

/// A small fleet: 2 robots × 2 joints × `days` of 3 s joint tests (5 speed levels), r2/j1
/// wearing from day 14.
fn small_fleet(dir: &Path, days: usize) {
    let d = days.to_string();
    hdw_ok(&[
        "synth",
        "fleet",
        "--robots",
        "2",
        "--joints",
        "2",
        "--days",
        &d,
        "--duration",
        "3",
        "--levels",
        "5",
        "--wear",
        "r2/j1@14",
        "--out",
        dir.to_str().unwrap(),
    ]);
}

fn read(path: &Path) -> Table {
    hd_io::read_table(path).unwrap()
}

/// The columns of a fleet's fits.parquet the template tests read, and its failed rows.
struct Fits {
    height: usize,
    status: Vec<Option<String>>,
    error: Vec<Option<String>>,
    fit: Vec<Option<String>>,
    param: Vec<Option<String>>,
    value: Vec<f64>,
    se: Vec<f64>,
    li: Vec<f64>,
    /// Rows whose status is not "ok".
    failed: Vec<usize>,
}

fn fits(path: &Path) -> Fits {
    let t = read(path);
    let text = |c: &str| t.text(c).unwrap().to_vec();
    let status = text("status");
    let failed = (0..t.height).filter(|&r| status[r].as_deref() != Some("ok")).collect();
    Fits {
        height: t.height,
        error: text("error"),
        fit: text("fit"),
        param: text("parameter"),
        value: t.num("value").unwrap().to_vec(),
        se: t.num("std_error").unwrap().to_vec(),
        li: t.num("log_index").unwrap().to_vec(),
        status,
        failed,
    }
}

/// The table without the wall-time column (which differs between runs).
fn without_time(t: &Table) -> Vec<(String, ColumnData)> {
    t.names
        .iter()
        .cloned()
        .zip(t.columns.iter().cloned())
        .filter(|(n, _)| n != "fit_time_s")
        .collect()
}

#[test]
fn bad_rows_are_failed_rows_and_the_worn_unit_is_flagged() {
    let dir = scratch("fleet-bad-rows");
    small_fleet(&dir.join("data"), 30);
    let manifest = std::fs::read_to_string(dir.join("data/manifest.csv")).unwrap();
    let mut lines: Vec<String> = manifest.lines().map(str::to_string).collect();
    // A log with other columns, a missing file, a duplicate, a bad timestamp, a missing
    // covariate: five rows that must fail (or, the covariate, go unnormalised) alone.
    std::fs::write(dir.join("data/other.csv"), "time,speed,torque\n0,1,2\n1,2,3\n").unwrap();
    lines.push("other.csv,r9,j9,2026-01-05,20".into());
    lines.push("logs/none.csv,r9,j8,2026-01-05,20".into());
    lines.push(lines[1].clone());
    lines.push("logs/r1/j1/2026-01-05.csv,r9,j7,5th of January,20".into());
    let cut = lines[5].rfind(',').unwrap();
    lines[5].truncate(cut + 1);
    std::fs::write(dir.join("data/manifest.csv"), lines.join("\n") + "\n").unwrap();
    let out = dir.join("fleet");
    hdw_ok(&[
        "fleet",
        "--manifest",
        dir.join("data/manifest.csv").to_str().unwrap(),
        "--covariates",
        "temperature",
        "--baseline-days",
        "10",
        "--out",
        out.to_str().unwrap(),
    ]);
    let t = read(&out.join("fits.parquet"));
    let status = t.text("status").unwrap();
    let error = t.text("error").unwrap();
    let li = t.num("log_index").unwrap();
    let reason = |row: usize| -> String {
        (0..t.height)
            .find(|&r| li[r] as usize == row)
            .and_then(|r| error[r].clone())
            .unwrap_or_default()
    };
    let n = 120;
    for r in n..n + 4 {
        eprintln!("row {r}: {}", reason(r));
    }
    assert!(reason(n).contains("other.csv") && reason(n).contains("'t'"), "{}", reason(n));
    assert!(reason(n + 1).contains("none.csv: no such file"), "{}", reason(n + 1));
    assert!(reason(n + 2).contains("duplicate of row 1"), "{}", reason(n + 2));
    assert!(reason(n + 3).contains("not a timestamp"), "{}", reason(n + 3));
    let failed: Vec<usize> = (0..t.height)
        .filter(|&r| status[r].as_deref() != Some("ok"))
        .map(|r| li[r] as usize)
        .collect();
    assert_eq!(failed, vec![n, n + 1, n + 2, n + 3]);
    // Every good log gives Tc, Ts, sigma2, ws.
    assert_eq!(t.height, 4 * n + 4);
    let alarms = std::fs::read_to_string(out.join("alarms.csv")).unwrap();
    let flagged: Vec<&str> = alarms.lines().skip(1).map(|l| l.split(',').next().unwrap()).collect();
    assert!(flagged.contains(&"r2/j1"), "{alarms}");
    assert!(flagged.iter().all(|u| *u == "r2/j1"), "a healthy unit alarmed:\n{alarms}");
    let d = read(&out.join("drift.parquet"));
    let notes = d.text("note").unwrap();
    assert!(notes.iter().flatten().any(|s| s.contains("covariate 'temperature' missing")));
    assert!(out.join("plots/overview.svg").exists() && out.join("plots/r2-j1-Tc.svg").exists());
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn shards_merged_give_the_one_run_table_and_an_interrupted_run_resumes() {
    let dir = scratch("fleet-shards");
    small_fleet(&dir.join("data"), 16);
    let m = dir.join("data/manifest.csv");
    let args = |out: &Path, extra: &[&str]| {
        let mut a = vec![
            "fleet",
            "--manifest",
            m.to_str().unwrap(),
            "--covariates",
            "temperature",
            "--baseline-days",
            "8",
            "--no-plots",
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        a.extend(extra.iter().map(|s| s.to_string()));
        a.push("--out".into());
        a.push(out.to_str().unwrap().into());
        a
    };
    let run = |a: Vec<String>| hdw_ok(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let one = dir.join("one");
    run(args(&one, &[]));
    let sh = dir.join("sh");
    for k in ["2/3", "1/3"] {
        run(args(&sh, &["--shard", k]));
    }
    // The merge refuses an incomplete set.
    let early = hdw(&["fleet", "--merge", "--baseline-days", "8", "--out", sh.to_str().unwrap()]);
    assert_one_line_error(&early, &["shards 3 of 3 have not finished"]);
    run(args(&sh, &["--shard", "3/3"]));
    hdw_ok(&[
        "fleet",
        "--merge",
        "--baseline-days",
        "8",
        "--no-plots",
        "--out",
        sh.to_str().unwrap(),
    ]);
    let (a, b) = (read(&one.join("fits.parquet")), read(&sh.join("fits.parquet")));
    assert_eq!(a.height, 64 * 4);
    assert_eq!(without_time(&a), without_time(&b));
    assert_eq!(read(&one.join("drift.parquet")), read(&sh.join("drift.parquet")));
    assert_eq!(
        std::fs::read_to_string(one.join("alarms.csv")).unwrap(),
        std::fs::read_to_string(sh.join("alarms.csv")).unwrap()
    );

    // Interrupted: kill it once a part is committed; --resume fits only the rest.
    let int = dir.join("int");
    let mut a =
        args(&int, &["--part-logs", "4", "--threads", "1", "--fit", "transient", "--params", "Tc"]);
    a.retain(|s| s != "--no-plots");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_hdw"))
        .args(&a)
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let parts = int.join("parts");
    let t0 = std::time::Instant::now();
    while std::fs::read_dir(&parts).map_or(0, |d| {
        d.filter(|e| e.as_ref().is_ok_and(|e| !e.file_name().to_string_lossy().starts_with('.')))
            .count()
    }) == 0
        && t0.elapsed().as_secs() < 60
    {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = std::process::Command::new("kill").args(["-INT", &child.id().to_string()]).status();
    let status = child.wait().unwrap();
    assert!(!status.success(), "the run finished before the interrupt; the test needs slower logs");
    assert!(!int.join("fits.parquet").exists());
    let mut resumed = a.clone();
    resumed.push("--resume".into());
    let out = run(resumed);
    let err = String::from_utf8_lossy(&out.stderr);
    let done: usize = err
        .split(", ")
        .find_map(|s| s.strip_suffix(" already fitted"))
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!((4..64).contains(&done), "{err}");
    let c = read(&int.join("fits.parquet"));
    let li = c.num("log_index").unwrap();
    let mut logs: Vec<u64> = li.iter().map(|v| *v as u64).collect();
    logs.dedup();
    assert_eq!(logs, (0..64).collect::<Vec<u64>>(), "every log once, in order");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_bad_manifest_or_setting_is_one_line() {
    let dir = scratch("fleet-refusals");
    let m = dir.join("m.csv");
    std::fs::write(&m, "file,robot,joint,date\nx.csv,r1,j1,2026-01-01\n").unwrap();
    let out = dir.join("o");
    let e = hdw(&[
        "fleet",
        "--manifest",
        m.to_str().unwrap(),
        "--covariates",
        "temp",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&e, &["m.csv", "no column 'temp'", "file, robot, joint, date"]);
    let e = hdw(&[
        "fleet",
        "--manifest",
        m.to_str().unwrap(),
        "--false-alarm",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&e, &["--false-alarm 2", "probability"]);
    let e = hdw(&[
        "fleet",
        "--pattern",
        &format!("{}/{{robot}}/{{date}}.csv", dir.display()),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&e, &["no file matches"]);
    std::fs::write(&m, "file,robot,joint,date,value\nx.csv,r1,j1,2026-01-01,3\n").unwrap();
    let e = hdw(&["fleet", "--manifest", m.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_one_line_error(&e, &["column 'value'", "rename it"]);
    let e = hdw(&["synth", "fleet", "--wear", "r9/j1@3", "--out", out.to_str().unwrap()]);
    assert_one_line_error(&e, &["--wear r9/j1@3", "robot 1..4"]);
    // A text covariate (a date, a name) left nothing to normalise and missed the wear.
    std::fs::write(
        &m,
        "file,robot,joint,date,temperature
x.csv,r1,j1,2026-01-01,warm
",
    )
    .unwrap();
    let e = hdw(&[
        "fleet",
        "--manifest",
        m.to_str().unwrap(),
        "--covariates",
        "temperature",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_one_line_error(&e, &["covariate column 'temperature' is not numeric", "row 1: 'warm'"]);
    std::fs::write(
        &m,
        "file,robot,joint,date
",
    )
    .unwrap();
    let e = hdw(&["fleet", "--manifest", m.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_one_line_error(&e, &["m.csv", "no logs"]);
    // Sizes a machine cannot hold are refused before any work (were allocation aborts).
    for (args, needle) in [
        (&["--duration", "1e9"][..], "samples a log"),
        (&["--robots", "100000", "--joints", "100000", "--days", "100000"][..], "logs, more than"),
    ] {
        let mut a = vec!["synth", "fleet"];
        a.extend(args);
        a.extend(["--out", out.to_str().unwrap()]);
        assert_one_line_error(&hdw(&a), &[needle]);
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// The hysteresis template: every torque–deflection log of a small fleet fitted with the
/// stiffness law `hdw fit hysteresis` fits (`--fit hysteresis --law memory`); each log's
/// c comes back near the truth the logs were made with, a log without the deflection
/// column is a failed row naming it, and a resumed run with another law is refused.
#[test]
fn the_hysteresis_template_fits_every_log_with_a_stiffness_law() {
    let dir = scratch("fleet-hysteresis");
    let data = dir.join("data");
    let mut manifest = vec!["file,robot,joint,date".to_string()];
    let c_true = 6.5e4;
    for (u, robot) in ["r1", "r2"].iter().enumerate() {
        for day in 1..=5 {
            let file = format!("logs/{robot}/j1/2026-03-0{day}.csv");
            let path = data.join(&file);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            let seed = (10 * u + day).to_string();
            hdw_ok(&[
                "synth",
                "hysteresis",
                "--set",
                &format!("c={c_true}"),
                "--samples",
                "4000",
                "--noise",
                "0.01",
                "--seed",
                &seed,
                "--out",
                path.to_str().unwrap(),
            ]);
            manifest.push(format!("{file},{robot},j1,2026-03-0{day}"));
        }
    }
    std::fs::write(data.join("other.csv"), "t,angle,torque\n0,0,0\n1,1,1\n").unwrap();
    manifest.push("other.csv,r3,j1,2026-03-01".into());
    std::fs::write(data.join("manifest.csv"), manifest.join("\n") + "\n").unwrap();
    let out = dir.join("fleet");
    let m = data.join("manifest.csv");
    let run = |law: &str, extra: &[&str]| {
        let mut a = vec![
            "fleet",
            "--manifest",
            m.to_str().unwrap(),
            "--fit",
            "hysteresis",
            "--law",
            law,
            "--baseline-days",
            "3",
            "--no-plots",
            "--out",
            out.to_str().unwrap(),
        ];
        a.extend(extra);
        hdw(&a)
    };
    let first = run("memory", &[]);
    assert!(first.status.success(), "{}", String::from_utf8_lossy(&first.stderr));
    let Fits { height, status, error, fit, param, value, se, li, failed } =
        fits(&out.join("fits.parquet"));
    assert_eq!(failed.len(), 1, "one failed row");
    let e = error[failed[0]].clone().unwrap_or_default();
    assert!(e.contains("other.csv") && e.contains("theta"), "{e}");
    assert_eq!(li[failed[0]] as usize, 10);
    let mut logs_with_c = 0;
    for r in (0..height).filter(|&r| status[r].as_deref() == Some("ok")) {
        assert_eq!(fit[r].as_deref(), Some("hysteresis-memory"));
        if param[r].as_deref() == Some("c") {
            logs_with_c += 1;
            assert!((value[r] / c_true - 1.0).abs() < 0.05, "c = {} on log {}", value[r], li[r]);
            assert!(se[r].is_finite() && se[r] > 0.0, "c's standard error {}", se[r]);
        }
    }
    assert_eq!(logs_with_c, 10, "every good log gives c");
    // The drift ran on the stiffness parameters.
    let d = read(&out.join("drift.parquet"));
    let tested = d.text("parameter").unwrap();
    assert!(tested.iter().flatten().any(|p| p == "c"));
    // Another law on the same folder is another template: refused.
    let other = run("bouc-wen", &["--resume"]);
    assert_one_line_error(&other, &["another fit template"]);
    let _ = std::fs::remove_dir_all(dir);
}

/// The drive template: every log fitted as `hdw fit drive` fits one record, with the
/// fleet's configuration whose `file` each log replaces. The EMPS record under three
/// names (two units) gives the same estimates three times; a file that is no MAT record is
/// a failed row naming it; a configuration with two records is refused in one line.
#[test]
fn the_drive_template_fits_every_log_as_fit_drive_does() {
    let dir = scratch("fleet-drive");
    let data = dir.join("data");
    let emps = crate::common::repo_path("data/emps/DATA_EMPS.mat");
    let mut manifest = vec!["file,robot,joint,date".to_string()];
    for (file, robot, date) in [
        ("u1/a.mat", "r1", "2026-01-01"),
        ("u1/b.mat", "r1", "2026-01-02"),
        ("u2/a.mat", "r2", "2026-01-01"),
    ] {
        let p = data.join(file);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::copy(&emps, &p).unwrap();
        manifest.push(format!("{file},{robot},j1,{date}"));
    }
    std::fs::write(data.join("bad.mat"), "not a MAT file").unwrap();
    manifest.push("bad.mat,r3,j1,2026-01-01".into());
    std::fs::write(data.join("manifest.csv"), manifest.join("\n") + "\n").unwrap();
    let cfg = std::fs::read_to_string(crate::common::repo_path("data/emps/fit.toml")).unwrap();
    let one_law: String = cfg
        .lines()
        .map(|l| if l.starts_with("friction") { "friction = \"coulomb-viscous\"" } else { l })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("fit.toml"), &one_law).unwrap();
    let out = dir.join("fleet");
    let args = |config: &Path, out: &Path| {
        hdw(&[
            "fleet",
            "--manifest",
            data.join("manifest.csv").to_str().unwrap(),
            "--fit",
            "drive",
            "--drive-config",
            config.to_str().unwrap(),
            "--baseline-days",
            "2",
            "--no-plots",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let run = args(&dir.join("fit.toml"), &out);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let Fits { height, status, error, fit, param, value, se, li, failed } =
        fits(&out.join("fits.parquet"));
    assert_eq!(failed.len(), 1);
    assert_eq!(li[failed[0]] as usize, 3);
    let e = error[failed[0]].clone().unwrap_or_default();
    assert!(e.contains("bad.mat") && e.contains("MAT"), "{e}");
    let masses: Vec<(f64, f64)> = (0..height)
        .filter(|&r| param[r].as_deref() == Some("M"))
        .map(|r| (value[r], se[r]))
        .collect();
    assert_eq!(masses.len(), 3, "every good log gives the mass");
    for &(m, s) in &masses {
        assert_eq!(m, masses[0].0, "the same record gives the same mass");
        assert!(s.is_finite() && s > 0.0 && s < 0.01 * m, "M = {m} ± {s}");
    }
    for r in (0..height).filter(|&r| status[r].as_deref() == Some("ok")) {
        assert_eq!(fit[r].as_deref(), Some("drive-coulomb-viscous"));
    }
    assert!(out.join("drift.parquet").exists());
    // Two records in the configuration: which would each log replace? Refused.
    let two = one_law.clone() + "\n[[experiment]]\nname = \"second\"\nfile = \"x.mat\"\n";
    std::fs::write(dir.join("two.toml"), two).unwrap();
    let refused = args(&dir.join("two.toml"), &dir.join("fleet-two"));
    assert_one_line_error(&refused, &["--drive-config", "2 `file =` keys"]);
    let _ = std::fs::remove_dir_all(dir);
}
