//! `read_columns` on files as rigs write them: mixed integer/decimal columns, extra columns,
//! tab and semicolon separators, comment lines, CRLF, BOM, names with spaces and brackets,
//! `.txt`/`.tsv`, Parquet of several numeric types, and errors that name the column and row.

use hd_io::{read_columns, read_table};
use polars::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Write `text` to `name` inside `dir`.
fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The error message of a read expected to fail.
fn error(path: &Path, names: &[&str]) -> String {
    match read_columns(path, names) {
        Ok(cols) => panic!("expected an error, read {} columns", cols.len()),
        Err(e) => e.to_string(),
    }
}

/// A 6000-row CSV whose `x` (and `junk`) hold integers except one decimal at `float_row`
/// (1-based data row), plus a text column.
fn mixed_csv(float_row: usize) -> String {
    let mut s = String::from("t,x,junk,label\n");
    for r in 1..=6000 {
        let x = if r == float_row { "0.142".to_string() } else { (r % 7).to_string() };
        let junk = if r >= float_row { format!("{}.5", r) } else { r.to_string() };
        writeln!(s, "{},{x},{junk},run-{r}", r as f64 * 1e-3).unwrap();
    }
    s
}

#[test]
fn mixed_integer_and_decimal_column_reads_wherever_the_decimal_first_appears() {
    let dir = tempfile::tempdir().unwrap();
    for float_row in [1, 2, 5000, 6000] {
        let path = write(dir.path(), "mixed.csv", &mixed_csv(float_row));
        let cols = read_columns(&path, &["t", "x"]).unwrap();
        assert_eq!(cols[1].len(), 6000);
        assert_eq!(cols[1][float_row - 1], 0.142, "decimal at row {float_row}");
        let other = if float_row == 1 { 1 } else { 0 };
        assert_eq!(cols[1][other], ((other + 1) % 7) as f64);
        assert_eq!(cols[0][5999], 6.0);
    }
}

#[test]
fn unused_columns_are_ignored_whatever_they_hold() {
    let dir = tempfile::tempdir().unwrap();
    // `junk` turns from integers to decimals at row 5000, `label` is text: neither is asked.
    let path = write(dir.path(), "mixed.csv", &mixed_csv(5000));
    let cols = read_columns(&path, &["t"]).unwrap();
    assert_eq!(cols.len(), 1);
    assert_eq!(cols[0].len(), 6000);
    assert_eq!(cols[0][4999], 5.0);
    // read_frame (used by the result-table readers) infers from every row too.
    let table = read_table(&path).unwrap();
    assert_eq!(table.num("junk").unwrap()[5999], 6000.5);
    assert_eq!(table.text("label").unwrap()[0].as_deref(), Some("run-1"));
}

#[test]
fn extra_columns_and_the_asked_order() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "extra.csv", "a,t,b,u,c\n9,0,8,1.5,x\n9,0.1,8,2.5,y\n");
    let cols = read_columns(&path, &["u", "t"]).unwrap();
    assert_eq!(cols, vec![vec![1.5, 2.5], vec![0.0, 0.1]]);
    // The same column twice is fine.
    let cols = read_columns(&path, &["t", "t"]).unwrap();
    assert_eq!(cols[0], cols[1]);
}

#[test]
fn tab_separated_txt_with_spaces_and_brackets_in_names() {
    let dir = tempfile::tempdir().unwrap();
    let text = "Time [s]\tNormal [uN]\tPosition [mm]\tFriction [uN]\n\
                0\t569.8\t-110.0355\t242.2\n\
                0.005\t519.9\t-110.0355\t249.3\n\
                0.01\t577\t-110.0354\t261\n";
    for name in ["rig.txt", "rig.tsv", "rig.csv"] {
        let path = write(dir.path(), name, text);
        let cols = read_columns(&path, &["Time [s]", "Position [mm]", "Friction [uN]"]).unwrap();
        assert_eq!(cols[0], [0.0, 0.005, 0.01], "{name}");
        assert_eq!(cols[1], [-110.0355, -110.0355, -110.0354], "{name}");
        assert_eq!(cols[2], [242.2, 249.3, 261.0], "{name}");
    }
    // read_frame (behind read_table) sniffs the separator and skips comments as well.
    let path = write(dir.path(), "commented.txt", &format!("# rig 2\n{text}"));
    let table = read_table(&path).unwrap();
    assert_eq!(table.names.len(), 4);
    assert_eq!(table.num("Friction [uN]").unwrap(), [242.2, 249.3, 261.0]);
}

#[test]
fn semicolon_separator_with_decimal_commas() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "eu.csv", "t;theta [rad];T\n0;1,5;2\n0,1;-2,25;3e-3\n");
    let cols = read_columns(&path, &["t", "theta [rad]", "T"]).unwrap();
    assert_eq!(cols, vec![vec![0.0, 0.1], vec![1.5, -2.25], vec![2.0, 3e-3]]);
}

#[test]
fn comment_lines_crlf_bom_quotes_and_trailing_blank_lines() {
    let dir = tempfile::tempdir().unwrap();
    let text = "\u{feff}# rig 3, run 12\r\n# operator: A. N. Other; 2025-01-31\r\n\
                \"t\", \"u [V]\" ,note\r\n0,1,\"a, b\"\r\n# paused\r\n0.5, 2 ,c\r\n\r\n\r\n";
    let path = write(dir.path(), "rig.csv", text);
    let cols = read_columns(&path, &["t", "u [V]"]).unwrap();
    assert_eq!(cols, vec![vec![0.0, 0.5], vec![1.0, 2.0]]);

    // A BOM directly before the header must not stick to the first name.
    let path = write(dir.path(), "bom.csv", "\u{feff}t,u\r\n0,1\r\n1,2\r\n");
    assert_eq!(read_columns(&path, &["t"]).unwrap(), vec![vec![0.0, 1.0]]);
    let profile = hd_io::read_profile(&path).unwrap();
    assert_eq!(profile.t, [0.0, 1.0]);
    assert_eq!(profile.u, [1.0, 2.0]);
}

#[test]
fn parquet_of_several_numeric_types_casts_to_f64() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("data.parquet");
    let mut df = df!(
        "i32" => [1i32, -2, 3],
        "i64" => [10i64, 20, 30],
        "f32" => [0.5f32, 1.25, -4.0],
        "u32" => [1u32, 2, 3],
        "flag" => [true, false, true],
        "text" => ["1.5", "2", "-3e2"],
        "label" => ["a", "b", "c"],
    )
    .unwrap();
    ParquetWriter::new(std::fs::File::create(&path).unwrap()).finish(&mut df).unwrap();
    let cols = read_columns(&path, &["f32", "i64", "i32", "u32", "text"]).unwrap();
    assert_eq!(cols[0], [0.5, 1.25, -4.0]);
    assert_eq!(cols[1], [10.0, 20.0, 30.0]);
    assert_eq!(cols[2], [1.0, -2.0, 3.0]);
    assert_eq!(cols[3], [1.0, 2.0, 3.0]);
    assert_eq!(cols[4], [1.5, 2.0, -300.0]);
    // A true/false column is no measurement (a boolean torque was fitted as 0/1).
    let e = read_columns(&path, &["f32", "flag"]).map(|_| ()).unwrap_err().to_string();
    assert!(e.contains("column 'flag' holds true/false values"), "{e}");

    let msg = error(&path, &["i32", "theta"]);
    assert!(msg.contains("data.parquet") && msg.contains("missing column 'theta'"), "{msg}");
    assert!(msg.contains("i32, i64, f32, u32, flag, text, label"), "{msg}");
    let msg = error(&path, &["label"]);
    assert!(msg.contains("column 'label', row 1: 'a' is not a number"), "{msg}");
}

#[test]
fn a_non_numeric_cell_names_file_column_and_row() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("# header comment\nt,x,y\n");
    for r in 1..=20 {
        let x = if r == 17 { "abc".to_string() } else { r.to_string() };
        writeln!(text, "{r},{x},oops").unwrap();
    }
    let path = write(dir.path(), "bad.csv", &text);
    let msg = error(&path, &["t", "x"]);
    println!("{msg}");
    assert!(msg.contains("bad.csv"), "{msg}");
    assert!(msg.contains("column 'x', row 17: 'abc' is not a number"), "{msg}");
    // Row counts data rows; the file line (comment + header + 17) is given too.
    assert!(msg.contains("(line 19)"), "{msg}");
    // `y` is never looked at unless asked.
    assert_eq!(read_columns(&path, &["t"]).unwrap()[0].len(), 20);
    let msg = error(&path, &["y"]);
    assert!(msg.contains("column 'y', row 1: 'oops' is not a number"), "{msg}");
}

#[test]
fn an_empty_cell_a_short_row_and_nan_name_the_row() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "gap.csv", "t,x,y\n0,1,2\n1,,3\n2,3,4\n");
    let msg = error(&path, &["t", "x"]);
    assert!(msg.contains("column 'x', row 2: empty cell; expected a number"), "{msg}");

    let path = write(dir.path(), "short.csv", "t,x,y\n0,1,2\n1,2\n");
    let msg = error(&path, &["t", "y"]);
    assert!(msg.contains("column 'y', row 2: missing"), "{msg}");
    assert!(msg.contains("field 3 of 3"), "{msg}");

    let path = write(dir.path(), "nan.csv", "t,x\n0,1\n1,NaN\n2,inf\n");
    let msg = error(&path, &["t", "x"]);
    assert!(msg.contains("column 'x', row 2: 'NaN' is not a finite number"), "{msg}");
}

#[test]
fn a_missing_column_lists_the_columns_present() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "cols.tsv", "Time [s]\tPosition [mm]\n0\t1\n");
    let msg = error(&path, &["Time [s]", "Speed [mm/s]"]);
    assert!(msg.contains("cols.tsv"), "{msg}");
    assert!(
        msg.contains("missing column 'Speed [mm/s]' (found: Time [s], Position [mm])"),
        "{msg}"
    );
    let msg = error(&path, &["time [s]"]);
    assert!(msg.contains("did you mean 'Time [s]'?"), "{msg}");

    let path = write(dir.path(), "dup.csv", "t,x,t\n0,1,2\n");
    let msg = error(&path, &["t"]);
    assert!(msg.contains("column 't' appears twice"), "{msg}");

    let path = write(dir.path(), "empty.csv", "# only a comment\n\n");
    let msg = error(&path, &["t"]);
    assert!(msg.contains("no header row"), "{msg}");
}

#[test]
fn a_header_without_rows_gives_empty_columns() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "head.csv", "t,u\n\n");
    assert_eq!(read_columns(&path, &["t", "u"]).unwrap(), vec![Vec::<f64>::new(), Vec::new()]);
}

#[test]
fn a_million_rows_read_in_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    let n = 1_000_000;
    let mut text = String::with_capacity(40 * n);
    text.push_str("t,x,unused\n");
    for r in 0..n {
        writeln!(text, "{},{},{}", r as f64 * 1e-4, r % 1000, r).unwrap();
    }
    let path = write(dir.path(), "big.csv", &text);
    let start = Instant::now();
    let cols = read_columns(&path, &["t", "x"]).unwrap();
    let secs = start.elapsed().as_secs_f64();
    println!("1e6 rows x 2 of 3 columns read in {secs:.2} s (this build's optimisation level)");
    assert_eq!(cols[0].len(), n);
    assert_eq!(cols[1][n - 1], ((n - 1) % 1000) as f64);
    assert!((cols[0][n - 1] - (n - 1) as f64 * 1e-4).abs() < 1e-9);
}

/// The real recording in `../shared/real-data` (tab-separated, names with brackets).
#[test]
fn the_real_tribometer_recording() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/real-data/tribometer-reciprocating.txt");
    if !path.is_file() {
        println!("note: {} is not present; skipping", path.display());
        return;
    }
    let start = Instant::now();
    let names = ["Time [s]", "Normal [uN]", "Position [mm]", "Friction [uN]"];
    let cols = read_columns(&path, &names).unwrap();
    println!("read 4 x {} values in {:.3} s", cols[0].len(), start.elapsed().as_secs_f64());
    assert!(cols.iter().all(|c| c.len() == 42_579));
    assert_eq!(cols[0][0], 0.0);
    assert_eq!(cols[0][42_578], 213.784);
    assert_eq!(cols[2][0], -110.0355);
    assert_eq!(cols[3][42_578], 2369.0);
    assert!(cols[0].windows(2).all(|w| w[1] > w[0]), "time increases");
}
