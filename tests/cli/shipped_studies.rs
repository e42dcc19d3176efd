//! The shipped studies: every file parses and expands to the documented number of runs,
//! and the small ones run end to end through `hdw study`.

use crate::common::*;

use std::path::{Path, PathBuf};
use std::process::Command;

fn studies_dir() -> PathBuf {
    repo_path("studies")
}

#[test]
fn every_shipped_study_parses_and_expands_to_its_documented_size() {
    let expected = [
        ("seed-variants", 3),
        ("seed-voltage", 24),
        ("table4", 6400),
        ("step", 25),
        ("freq-response", 345),
        ("limit-cycles", 176),
        ("hysteresis-energy", 100),
        ("global-sensitivity", 3840),
        ("morris-screening", 560),
        ("control", 162),
        ("hunting", 48),
        ("closed-loop-bode", 45),
        ("efficiency-map", 28),
        ("stiffness-laws", 12),
    ];
    let loader = |p: &Path| hd_io::read_profile(p).map_err(|e| e.to_string());
    let mut files: Vec<PathBuf> = std::fs::read_dir(studies_dir())
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert_eq!(
        files.len(),
        expected.len(),
        "a study was added or removed: update this test and studies/README.md"
    );
    for (name, runs) in expected {
        let study = hd_sweep::load_study(&studies_dir().join(format!("{name}.toml")), &loader)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(study.name, name);
        assert_eq!(study.expand().len(), runs, "{name}");
    }
}

#[test]
fn the_small_shipped_studies_run_end_to_end() {
    for name in ["seed-variants", "step"] {
        let out = std::env::temp_dir().join(format!("hdw-shipped-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let file = studies_dir().join(format!("{name}.toml"));
        let run = Command::new(env!("CARGO_BIN_EXE_hdw"))
            .args(["study", file.to_str().unwrap(), "--out", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(run.status.success(), "{name}: {}", String::from_utf8_lossy(&run.stderr));
        let t = hd_io::read_table(&out.join("runs.parquet")).unwrap();
        assert!(t.text("status").unwrap().iter().all(|s| s.as_deref() == Some("ok")), "{name}");
        let report = std::fs::read_to_string(out.join("report.md")).unwrap();
        assert!(
            report.contains("![") && out.join("traces.parquet").exists(),
            "{name}: plots and traces"
        );
    }
}

/// The closed-loop Bode study: `freq` sweeps the sine reference, every run records that
/// frequency, and the report draws the Bode figure with its summary table.
#[test]
fn closed_loop_bode_study_draws_its_bode_plot() {
    let out = std::env::temp_dir().join(format!("hdw-shipped-{}-clbode", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let file = studies_dir().join("closed-loop-bode.toml");
    let run = Command::new(env!("CARGO_BIN_EXE_hdw"))
        .args(["study", file.to_str().unwrap(), "--part", "linear", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let t = hd_io::read_table(&out.join("runs.parquet")).unwrap();
    let freq = t.num("freq").unwrap();
    assert!((freq.iter().copied().fold(f64::NAN, f64::max) - 50.0).abs() < 1e-9, "{freq:?}");
    let gain = t.num("gain_db").unwrap();
    assert!((gain[0] - 0.7423).abs() < 1e-3, "closed-loop gain at 1 Hz: {}", gain[0]);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("closed-loop-bode-linear-bode.svg"), "{report}");
    assert!(out.join("closed-loop-bode-linear-bode.svg").exists());
    let _ = std::fs::remove_dir_all(&out);
}
