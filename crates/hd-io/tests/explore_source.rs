//! Folders of shards, patterns and single files read as one table.

mod explore_fixtures;

use explore_fixtures::{rows, runs_table, traces_table};
use hd_io::explore::{Dataset, Kind, write_table};

#[test]
fn a_folder_of_shards_reads_as_one_table() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let all = runs_table();
    write_table(&d.join("runs-shard-1-of-2.parquet"), &rows(&all, 0..4)).unwrap();
    write_table(&d.join("runs-shard-2-of-2.parquet"), &rows(&all, 4..6)).unwrap();
    // Neither traces, nor parts of an unfinished sweep, nor temporary files are read.
    write_table(&d.join("traces.parquet"), &traces_table()).unwrap();
    std::fs::create_dir(d.join("parts")).unwrap();
    write_table(&d.join("parts/runs-all-000000.parquet"), &rows(&all, 0..2)).unwrap();
    std::fs::write(d.join(".runs.parquet.tmp-1"), b"half a file").unwrap();

    let ds = Dataset::open(&d.display().to_string(), None).unwrap();
    assert_eq!(ds.source().kind, Kind::Runs);
    assert_eq!(ds.source().files.len(), 2);
    let s = ds.summary().unwrap();
    assert_eq!(s.fact("rows").unwrap().as_u64(), Some(6));
    assert_eq!(s.fact("failed").unwrap().as_u64(), Some(1));
    let metrics = &s.section("metrics").unwrap().table;
    assert_eq!(metrics.num("median").unwrap()[0], 3.0); // thz_amp of the 5 ok runs
    assert_eq!(metrics.num("count").unwrap()[0], 5.0);
    let failed = &s.section("failed_runs").unwrap().table;
    assert_eq!(failed.text("run_id").unwrap()[0].as_deref(), Some("r3"));

    let pattern = d.join("runs-shard-*.parquet").display().to_string();
    let ds = Dataset::open(&pattern, None).unwrap();
    assert_eq!(ds.source().files.len(), 2);

    let traces = Dataset::open(&d.display().to_string(), Some(Kind::Traces)).unwrap();
    assert!(traces.has_column("theta_z"));
}

#[test]
fn mixed_kinds_and_different_columns_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_table(&d.join("runs.parquet"), &runs_table()).unwrap();
    write_table(&d.join("traces.parquet"), &traces_table()).unwrap();
    let e = Dataset::open(&d.join("*.parquet").display().to_string(), None).err().unwrap();
    assert!(e.to_string().contains("both run tables and traces"), "{e}");

    let mut other = rows(&runs_table(), 0..2);
    other.names[4] = "c".into();
    write_table(&d.join("runs-shard-2-of-2.parquet"), &other).unwrap();
    let e = Dataset::open(&d.display().to_string(), None).err().unwrap();
    assert!(e.to_string().contains("different columns") && e.to_string().contains("Kbar"), "{e}");

    let empty = tempfile::tempdir().unwrap();
    std::fs::create_dir(empty.path().join("parts")).unwrap();
    let e = Dataset::open(&empty.path().display().to_string(), None).err().unwrap();
    assert!(e.to_string().contains("unfinished sweep"), "{e}");
}

#[test]
fn curves_and_grids_for_plots() {
    let dir = tempfile::tempdir().unwrap();
    let runs = dir.path().join("runs.parquet");
    write_table(&runs, &runs_table()).unwrap();
    let ds = Dataset::open(&runs.display().to_string(), None).unwrap();
    let g = ds.grid("Kbar", "voltage", "thz_amp", hd_io::explore::AggFn::Mean).unwrap();
    assert_eq!((g.xs.clone(), g.ys.clone()), (vec![1e5, 2e5, 4e5], vec![12.0, 24.0]));
    assert_eq!(g.values[0], 2.0);
    assert_eq!(g.most_per_cell, 2);
    let (c, most) =
        ds.curves("Kbar", "thz_amp", Some("voltage"), Some(hd_io::explore::AggFn::Max)).unwrap();
    assert_eq!(c.len(), 2);
    assert_eq!((c[0].name.as_str(), c[0].y.clone()), ("voltage=12", vec![3.0, 3.0, 5.0]));
    assert_eq!(most, 2);

    let traces = dir.path().join("traces.parquet");
    write_table(&traces, &traces_table()).unwrap();
    let ds = Dataset::open(&traces.display().to_string(), None).unwrap();
    let ds = ds.where_in("run_id", &[hd_io::explore::Key::Text(Some("r1".into()))]).unwrap();
    let (c, _) = ds.curves("theta", "Tb", Some("run_id"), None).unwrap();
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].y, [0.0, 9.0, -9.0]);
}
