//! Pivot and group-by tables of a known small runs table.

mod explore_fixtures;

use explore_fixtures::{num, same, write_runs};
use hd_io::explore::{Dataset, parse_aggs, parse_pivot, parse_sort};

#[test]
fn pivot_of_a_known_table_gives_the_expected_cells() {
    let dir = tempfile::tempdir().unwrap();
    let ds = Dataset::open(&write_runs(dir.path()), None).unwrap();
    let report = ds.pivot(&parse_pivot("Kbar,voltage,thz_amp").unwrap(), None).unwrap();
    let t = &report.section("pivot").unwrap().table;
    assert_eq!(t.names, ["Kbar", "voltage=12", "voltage=24"]);
    assert_eq!(num(t, "Kbar"), [1e5, 2e5, 4e5]);
    // (1e5, 12) holds two runs (1 and 3); (2e5, 24) only the failed run; (4e5, 24) none.
    assert!(same(num(t, "voltage=12"), &[2.0, 3.0, 5.0]));
    assert!(same(num(t, "voltage=24"), &[2.0, f64::NAN, f64::NAN]));

    let counts = ds.pivot(&parse_pivot("Kbar,voltage,thz_amp:count").unwrap(), None).unwrap();
    let t = &counts.sections[0].table;
    assert!(same(num(t, "voltage=12"), &[2.0, 1.0, 1.0]));
    assert!(same(num(t, "voltage=24"), &[1.0, 0.0, f64::NAN]));
    assert!(counts.sections[0].title.starts_with("thz_amp (count) by Kbar"));
    assert!(report.sections[0].title.starts_with("thz_amp [rad] (mean)"));
}

#[test]
fn pivot_rows_by_text_and_sorted_descending() {
    let dir = tempfile::tempdir().unwrap();
    let ds = Dataset::open(&write_runs(dir.path()), None).unwrap();
    let spec = parse_pivot("variant,voltage,tb_peak:max").unwrap();
    let sort = parse_sort("voltage=12:desc").unwrap();
    let t = ds.pivot(&spec, Some(&sort)).unwrap().sections[0].table.clone();
    let names: Vec<_> = t.text("variant").unwrap().iter().flatten().cloned().collect();
    assert_eq!(names, ["linear", "full", "damped"]);
    assert!(same(num(&t, "voltage=12"), &[50.0, 40.0, 30.0]));
}

#[test]
fn group_by_counts_failures_and_aggregates() {
    let dir = tempfile::tempdir().unwrap();
    let ds = Dataset::open(&write_runs(dir.path()), None).unwrap();
    let aggs = parse_aggs(&["thz_amp:max,tb_peak:mean".into()]).unwrap();
    let r = ds.group_by(&["variant".into()], &aggs, None).unwrap();
    let t = &r.sections[0].table;
    assert_eq!(t.names, ["variant", "n", "failed", "thz_amp_max", "tb_peak_mean"]);
    assert!(same(num(t, "n"), &[2.0, 3.0, 1.0]));
    assert!(same(num(t, "failed"), &[1.0, 0.0, 0.0]));
    assert!(same(num(t, "thz_amp_max"), &[3.0, 3.0, 5.0]));
    assert!(same(num(t, "tb_peak_mean"), &[30.0, 70.0 / 3.0, 50.0]));
    assert_eq!(r.sections[0].units[3], "rad");

    let sorted = ds.group_by(&[], &aggs, Some(&parse_sort("n").unwrap())).unwrap();
    assert_eq!(num(&sorted.sections[0].table, "n"), [6.0]);
    let bad = ds.group_by(&["variant".into()], &aggs, Some(&parse_sort("nope").unwrap()));
    assert!(bad.unwrap_err().to_string().contains("nope"));
}
