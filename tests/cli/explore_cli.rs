//! `hdw explore` and `hdw plot` on small tables written for the test.

use crate::common::*;

use hd_io::explore::write_table;
use hd_io::{ColumnData, Table};
use std::path::Path;
use std::process::Output;

fn text(v: &[&str]) -> ColumnData {
    ColumnData::Text(v.iter().map(|s| Some(s.to_string())).collect())
}

/// Six runs over Kbar × voltage, one failed, split into two shards in `dir`.
fn write_shards(dir: &Path) {
    let nan = f64::NAN;
    let names = ["run_id", "variant", "status", "Kbar", "voltage", "thz_amp"];
    let table = |rows: std::ops::Range<usize>| {
        let all = [
            text(&["r0", "r1", "r2", "r3", "r4", "r5"]),
            text(&["full", "full", "damped", "damped", "full", "linear"]),
            text(&["ok", "ok", "ok", "failed", "ok", "ok"]),
            ColumnData::Num(vec![1e5, 1e5, 2e5, 2e5, 1e5, 4e5]),
            ColumnData::Num(vec![12.0, 24.0, 12.0, 24.0, 12.0, 12.0]),
            ColumnData::Num(vec![1.0, 2.0, 3.0, nan, 3.0, 5.0]),
        ];
        let columns = all
            .into_iter()
            .map(|c| match c {
                ColumnData::Num(v) => ColumnData::Num(v[rows.clone()].to_vec()),
                ColumnData::Text(v) => ColumnData::Text(v[rows.clone()].to_vec()),
            })
            .collect();
        Table { names: names.map(String::from).to_vec(), columns, height: rows.len() }
    };
    write_table(&dir.join("runs-shard-1-of-2.parquet"), &table(0..3)).unwrap();
    write_table(&dir.join("runs-shard-2-of-2.parquet"), &table(3..6)).unwrap();
    let t: Vec<f64> = (0..50).map(|k| k as f64 * 1e-3).collect();
    let theta: Vec<f64> = t.iter().map(|t| 1e-4 * (200.0 * t).sin()).collect();
    let traces = Table {
        names: ["run_id", "t", "theta_z", "theta", "Tb"].map(String::from).to_vec(),
        columns: vec![
            ColumnData::Text(
                (0..100).map(|k| Some(if k < 50 { "r0" } else { "r1" }.to_string())).collect(),
            ),
            ColumnData::Num([t.clone(), t.clone()].concat()),
            ColumnData::Num([theta.clone(), theta.iter().map(|x| 2.0 * x).collect()].concat()),
            ColumnData::Num([theta.clone(), theta.clone()].concat()),
            ColumnData::Num(
                [
                    theta.iter().map(|x| 3e4 * x).collect::<Vec<_>>(),
                    theta.iter().map(|x| 5e4 * x).collect(),
                ]
                .concat(),
            ),
        ],
        height: 100,
    };
    write_table(&dir.join("traces.parquet"), &traces).unwrap();
}

fn stdout(o: &Output) -> String {
    assert!(o.status.success(), "hdw failed: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn explore_reads_shards_as_one_table() {
    let dir = tempfile::tempdir().unwrap();
    write_shards(dir.path());
    let d = dir.path().to_str().unwrap();
    let out = stdout(&hdw(&["explore", d]));
    assert!(out.contains("rows: 6") && out.contains("failed: 1"), "{out}");
    assert!(out.contains("thz_amp") && out.contains("rad"), "{out}");

    let csv = stdout(&hdw(&["explore", d, "--pivot", "Kbar,voltage,thz_amp", "--format", "csv"]));
    assert_eq!(csv, "Kbar,voltage=12,voltage=24\n100000,2,2\n200000,3,\n400000,5,\n");

    let json = stdout(&hdw(&[
        "explore",
        d,
        "--filter",
        "status == \"ok\"",
        "--group-by",
        "variant",
        "--agg",
        "thz_amp:max",
        "--sort",
        "thz_amp_max:desc",
        "--format",
        "json",
    ]));
    let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(doc["rows"][0]["variant"], "linear");
    assert_eq!(doc["rows"][0]["thz_amp_max"], 5.0);
    assert_eq!(doc["rows_units"]["thz_amp_max"], "rad");
}

#[test]
fn a_bad_filter_fails_naming_the_token() {
    let dir = tempfile::tempdir().unwrap();
    write_shards(dir.path());
    let o =
        hdw(&["explore", dir.path().to_str().unwrap(), "--filter", "Kbar > 5e5 or voltage < 3"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("\"or\" at position 12"), "{err}");
}

/// The file exists, is not empty and starts like an SVG or a PNG.
fn assert_plot(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let svg = bytes.starts_with(b"<svg") || bytes.starts_with(b"<?xml");
    assert!(bytes.len() > 1000 && (svg || bytes.starts_with(b"\x89PNG")), "{}", path.display());
}

#[test]
fn every_plot_kind_writes_a_file() {
    let dir = tempfile::tempdir().unwrap();
    write_shards(dir.path());
    let d = dir.path().to_str().unwrap();
    let out = dir.path().join("plots");
    let p = |name: &str| out.join(name).to_str().unwrap().to_string();

    let heat = p("heat.svg");
    stdout(&hdw(&[
        "plot", d, "--x", "Kbar", "--y", "voltage", "--color", "thz_amp", "--out", &heat,
    ]));
    assert_plot(Path::new(&heat));

    let facets = p("facet.png");
    let args = ["plot", d, "--x", "Kbar", "--y", "voltage", "--color", "thz_amp"];
    stdout(&hdw(&[&args[..], &["--facet", "variant", "--out", &facets]].concat()));
    for v in ["damped", "full", "linear"] {
        assert_plot(&out.join(format!("facet-variant-{v}.png")));
    }

    let lines = p("lines.svg");
    let args = ["plot", d, "--x", "Kbar", "--line", "thz_amp", "--by", "variant", "--log-x"];
    stdout(&hdw(&[&args[..], &["--out", &lines]].concat()));
    assert_plot(Path::new(&lines));

    let signal = p("signal.svg");
    stdout(&hdw(&[
        "plot", d, "--run", "r0", "--run", "r1", "--x", "t", "--line", "theta_z", "--out", &signal,
    ]));
    assert_plot(Path::new(&signal));

    let lp = p("loop.png");
    let traces = dir.path().join("traces.parquet");
    stdout(&hdw(&["plot", traces.to_str().unwrap(), "--loop", "--out", &lp]));
    assert_plot(Path::new(&lp));

    let o = hdw(&["plot", d, "--run", "r9", "--loop", "--out", &p("none.svg")]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("no trace of run r9"));
}
