//! `--filter` expressions on a known table, and the errors they give.

mod explore_fixtures;

use explore_fixtures::write_runs;
use hd_io::explore::{Dataset, ExploreError};

fn rows_after(filters: &[&str]) -> Result<u64, ExploreError> {
    let dir = tempfile::tempdir().unwrap();
    let ds = Dataset::open(&write_runs(dir.path()), None)?;
    let filters: Vec<String> = filters.iter().map(|s| s.to_string()).collect();
    let r = ds.filtered(&filters)?.summary()?;
    Ok(r.fact("rows").and_then(|v| v.as_u64()).unwrap())
}

#[test]
fn filters_select_the_expected_rows() {
    assert_eq!(rows_after(&[r#"status == "ok""#]).unwrap(), 5);
    assert_eq!(rows_after(&["Kbar > 1.5e5"]).unwrap(), 3);
    assert_eq!(rows_after(&["variant in [full, damped]"]).unwrap(), 5);
    assert_eq!(rows_after(&["variant in ['linear']", "voltage <= 12"]).unwrap(), 1);
    assert_eq!(rows_after(&["status != ok", "Kbar>=2e5"]).unwrap(), 1);
}

#[test]
fn a_filter_error_names_the_token_it_could_not_read() {
    let e = rows_after(&["Kbar >> 5"]).unwrap_err().to_string();
    assert!(e.contains("'>'") || e.contains("\">\""), "{e}");
    assert!(e.contains("position 7"), "{e}");

    let e = rows_after(&["Kbar > 5 and voltage < 3"]).unwrap_err().to_string();
    assert!(e.contains("\"and\"") && e.contains("repeat --filter"), "{e}");

    let e = rows_after(&["Kbarr > 5"]).unwrap_err().to_string();
    assert!(e.contains("\"Kbarr\"") && e.contains("did you mean 'Kbar'"), "{e}");

    let e = rows_after(&["Kbar > soft"]).unwrap_err().to_string();
    assert!(e.contains("\"soft\"") && e.contains("holds numbers"), "{e}");

    let e = rows_after(&["variant < full"]).unwrap_err().to_string();
    assert!(e.contains("numeric column"), "{e}");

    let e = rows_after(&["status = ok"]).unwrap_err().to_string();
    assert!(e.contains("did you mean '=='"), "{e}");
}
