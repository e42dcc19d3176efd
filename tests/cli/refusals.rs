//! Ambiguous, oversized or mistaken inputs refused with a one-line error (issue #39):
//! each was accepted (silently wrong) or crashed before.

use crate::common::{assert_one_line_error, hdw, hdw_ok, scratch};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn two_names_for_one_parameter_are_refused_everywhere() {
    let dir = scratch("refuse-alias");
    let o = dir.join("o");
    let r = hdw(&["simulate", "--set", "A=3e4", "--set", "mem_A=4e4", "--out", s(&o)]);
    assert_one_line_error(&r, &["two names for one parameter", "mem_A"]);
    let params = dir.join("p.toml");
    std::fs::write(&params, "A = 3e4\nmem_A = 4e4\n").unwrap();
    let r = hdw(&["simulate", "--params", s(&params), "--out", s(&o)]);
    assert_one_line_error(&r, &["p.toml:", "two names for one parameter"]);
    let study = dir.join("st.toml");
    std::fs::write(
        &study,
        "name = \"st\"\n[base]\nt_end = 0.01\n[base.set]\nA = 3e4\nmem_A = 4e4\n",
    )
    .unwrap();
    let r = hdw(&["study", s(&study), "--out", s(&o)]);
    assert_one_line_error(&r, &["st.toml", "two names for one parameter"]);
    assert!(!o.exists());
}

#[test]
fn settings_files_are_checked_by_size_and_type_before_parsing() {
    let dir = scratch("refuse-settings");
    let o = dir.join("o");
    let r = hdw(&["simulate", "--params", "/dev/zero", "--out", s(&o)]);
    assert_one_line_error(&r, &["/dev/zero", "not a regular file"]);
    let big = dir.join("big.csv");
    std::fs::write(&big, "t,u\n0,1\n".repeat(700_000)).unwrap();
    let r = hdw(&["simulate", "--params", s(&big), "--out", s(&o)]);
    assert_one_line_error(&r, &["big.csv", "bytes, more than the"]);
    let study = dir.join("st.toml");
    std::fs::write(&study, "name = \"st\"\n[base]\nparams_file = \"/dev/zero\"\n").unwrap();
    let r = hdw(&["study", s(&study), "--out", s(&o)]);
    assert_one_line_error(&r, &["not a regular file"]);
}

#[test]
fn data_files_that_are_compressed_binary_or_folders_are_named_as_such() {
    let dir = scratch("refuse-binary");
    let gz = dir.join("rig.csv");
    std::fs::write(&gz, [0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3, 0xff, 0xfe, 0, 1]).unwrap();
    let r = hdw(&["fit", "hysteresis", s(&gz), "--out", s(&dir.join("f"))]);
    assert_one_line_error(&r, &["rig.csv", "gzip-compressed"]);
    let r = hdw(&["fit", "hysteresis", s(&dir), "--out", s(&dir.join("f"))]);
    assert_one_line_error(&r, &["is a folder"]);
}

#[test]
fn columns_mapped_twice_and_rows_with_extra_fields_are_refused() {
    let dir = scratch("refuse-columns");
    let csv = dir.join("d.csv");
    std::fs::write(&csv, "t,theta,torque\n0,0,0\n0.1,1e-4,2,76\n0.2,2e-4,5\n").unwrap();
    let r = hdw(&["fit", "hysteresis", s(&csv), "--columns", "t,t,torque", "--out", s(&dir)]);
    assert_one_line_error(&r, &["'t' is named twice"]);
    let r = hdw(&["fit", "hysteresis", s(&csv), "--out", s(&dir.join("f"))]);
    assert_one_line_error(&r, &["row 2", "4 comma-separated fields but the header has 3"]);
}

#[test]
fn study_files_with_repeats_zero_budgets_or_escaping_names_are_refused() {
    let dir = scratch("refuse-study");
    let o = dir.join("o");
    let write = |text: &str| {
        let f = dir.join("st.toml");
        std::fs::write(&f, text).unwrap();
        f
    };
    let f = write("name = \"r\"\n[[axis]]\nname = \"voltage\"\nvalues = [12, 12, 12]\n");
    assert_one_line_error(
        &hdw(&["study", s(&f), "--out", s(&o)]),
        &["values 1 and 2 are the same"],
    );
    let f = write("name = \"z\"\n[solver]\nmax_steps = 0\n");
    assert_one_line_error(&hdw(&["study", s(&f), "--out", s(&o)]), &["max_steps"]);
    let f = write("name = \"../../escape\"\n");
    assert_one_line_error(&hdw(&["study", s(&f)]), &["not a folder name"]);
    let f = write("name = \"t\"\n");
    assert_one_line_error(
        &hdw(&["study", s(&f), "--threads", "100000", "--out", s(&o)]),
        &["--threads 100000", "expected 1 to"],
    );
    assert!(!o.exists());
}

#[test]
fn another_studys_folder_is_refused_without_leaving_anything() {
    let dir = scratch("refuse-other");
    let o = dir.join("o");
    let a = dir.join("a.toml");
    std::fs::write(&a, "name = \"a\"\n[base]\nt_end = 0.01\n").unwrap();
    let b = dir.join("b.toml");
    std::fs::write(&b, "name = \"b\"\n[base]\nt_end = 0.02\n").unwrap();
    hdw_ok(&["study", s(&a), "--out", s(&o), "--no-report"]);
    let before = std::fs::read_dir(&o).unwrap().count();
    for extra in [&[][..], &["--resume"][..]] {
        let r = hdw(&[&["study", s(&b), "--out", s(&o)][..], extra].concat());
        assert_one_line_error(&r, &["holds the results of study 'a', not 'b'"]);
    }
    assert_eq!(std::fs::read_dir(&o).unwrap().count(), before);
    assert!(!o.join("parts").exists());
}

#[test]
fn counts_that_size_memory_are_limited() {
    let dir = scratch("refuse-counts");
    let r = hdw(&["sensitivity", "--check", "ishigami", "--samples", "1000000000"]);
    assert_one_line_error(&r, &["--samples 1000000000", "at most"]);
    let r = hdw(&["sensitivity", "--check", "ishigami", "--bootstrap", "1000000000"]);
    assert_one_line_error(&r, &["--bootstrap 1000000000", "at most"]);
    let r =
        hdw(&["synth", "hysteresis", "--samples", "10000000000", "--out", s(&dir.join("x.csv"))]);
    assert_one_line_error(&r, &["rows, more than"]);
}

#[test]
fn extreme_datasheet_values_and_negative_times_get_clear_errors() {
    let dir = scratch("refuse-values");
    let o = dir.join("ds");
    let r = hdw(&[
        "datasheet",
        "--k1",
        "1e308",
        "--k2",
        "1e308",
        "--k3",
        "1e308",
        "--t1",
        "29",
        "--t2",
        "108",
        "--out",
        s(&o),
    ]);
    assert_one_line_error(&r, &["a params file cannot hold"]);
    assert!(!o.exists());
    let r = hdw(&["simulate", "--t-end", "-1", "--out", s(&dir.join("s"))]);
    assert_one_line_error(&r, &["t_end = -1", "> 0"]);
}

#[test]
fn a_log_axis_says_how_many_points_it_leaves_out() {
    let dir = scratch("refuse-log");
    let run = dir.join("run");
    hdw_ok(&["simulate", "--t-end", "0.05", "--out", s(&run)]);
    let r = hdw_ok(&[
        "plot",
        s(&run.join("trace.parquet")),
        "--x",
        "theta_z",
        "--line",
        "Tb",
        "--log-x",
        "--out",
        s(&dir.join("p.svg")),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("--log-x leaves out") && err.contains("theta_z <= 0"), "{err}");
}
