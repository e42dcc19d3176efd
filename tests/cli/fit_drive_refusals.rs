//! `hdw fit drive` under bad input (issue #51): every number of a configuration, every file
//! it reads and its output folder checked before any fit work, each refusal one line naming
//! the file and the key. Before these checks several of the cases ran at full CPU for
//! minutes (nalgebra's SVD on a non-finite matrix); each test here fails before fitting.

use crate::common::{assert_one_line_error, fit_drive, hdw, repo_path, scratch};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The shipped EMPS configuration reading the shipped record by its absolute path, with
/// `replace` pairs applied and `tables` appended.
fn emps(replace: &[(&str, &str)], tables: &str) -> String {
    let data = repo_path("data/emps/DATA_EMPS.mat");
    let mut text = std::fs::read_to_string(repo_path("data/emps/fit.toml"))
        .unwrap()
        .replace("file = \"DATA_EMPS.mat\"", &format!("file = {:?}", s(&data)));
    for (a, b) in replace {
        assert!(text.contains(a), "{a}");
        text = text.replacen(a, b, 1);
    }
    text + tables
}

/// Run `fit drive` on configuration `text` written as `name` in a scratch folder; it must
/// fail within a few seconds in one line holding every needle, leaving no fit.json.
fn refused(name: &str, text: &str, needles: &[&str]) {
    let dir = scratch(&format!("fdr-{name}"));
    let cfg = dir.join(format!("{name}.toml"));
    std::fs::write(&cfg, text).unwrap();
    refused_at(&cfg, &dir.join("out"), &[], needles);
}

/// Run `fit drive --config cfg --out out` (and `more`): refused quickly in one line.
fn refused_at(cfg: &Path, out: &Path, more: &[&str], needles: &[&str]) {
    let t0 = Instant::now();
    let mut args = vec!["fit", "drive", "--config", s(cfg), "--out", s(out)];
    args.extend(more);
    let o = hdw(&args);
    assert!(t0.elapsed() < Duration::from_secs(20), "{:?} for {needles:?}", t0.elapsed());
    assert_one_line_error(&o, needles);
    assert!(!out.join("fit.json").exists());
}

#[test]
fn emps_negative_mass_is_refused_before_the_fit() {
    refused("mass", &emps(&[], "[params]\nM = -5.0\n"), &["mass.toml, [params] M", "> 0"]);
    refused("mass-nan", &emps(&[], "[params]\nM = nan\n"), &["[params] M", "finite"]);
}

#[test]
fn emps_bounds_that_exclude_the_start_are_refused() {
    let cv = ("friction = \"all\"", "friction = \"coulomb-viscous\"");
    refused(
        "bounds",
        &emps(&[cv], "[bounds]\nM = [1.0, 2.0]\n"),
        &["bounds.toml, [bounds] M", "excludes the start", "inverse-model"],
    );
    refused(
        "bounds-order",
        &emps(&[], "[bounds]\nM = [2.0, 1.0]\n"),
        &["[bounds] M", "lower < upper"],
    );
    refused("bounds-nan", &emps(&[], "[bounds]\nFc = [nan, 1.0]\n"), &["[bounds] Fc"]);
}

#[test]
fn emps_lugre_negative_bristle_stiffness_is_refused() {
    let text = emps(&[("friction = \"all\"", "friction = \"lugre\"")], "[params]\nsigma0 = -1.0\n");
    refused("sigma0", &text, &["[params] sigma0", "bristle stiffness"]);
}

#[test]
fn emps_gain_scales_and_controller_numbers_are_checked() {
    for (k, (a, b), key) in [
        (0, ("gain = \"gtau\"", "gain = nan"), "gain"),
        (1, ("gain = \"gtau\"", "gain = inf"), "gain"),
        (2, ("gain = \"gtau\"", "gain = 0"), "gain"),
        (3, ("gain = \"gtau\"", "gain = -35.15"), "gain"),
        (4, ("command = \"vir\"", "command = \"vir\"\nposition_scale = 0.0"), "position_scale"),
        (5, ("command = \"vir\"", "command = \"vir\"\ncommand_scale = nan"), "command_scale"),
        (6, ("kp = \"kp\"", "kp = nan"), "[controller] kp"),
        (7, ("kv = \"kv\"", "kv = -1.0"), "[controller] kv"),
        (8, ("speed_filter = [0.5, 0.5]", "speed_filter = [nan]"), "[controller] speed_filter"),
        (9, ("delay = \"auto\"", "delay = -1"), "[controller] delay"),
        (10, ("cutoff_hz = 40.0", "cutoff_hz = 4000.0"), "[start] cutoff_hz"),
    ] {
        let name = format!("num{k}");
        refused(&name, &emps(&[(a, b)], ""), &[&format!("{name}.toml, "), key]);
    }
}

#[test]
fn delay_negative_gets_a_plain_sentence() {
    let dir = scratch("fdr-delay");
    let cfg = dir.join("d.toml");
    std::fs::write(&cfg, emps(&[("delay = \"auto\"", "delay = -1")], "")).unwrap();
    let o = fit_drive(&cfg, &dir.join("out"));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("untagged") && err.contains("number of samples"), "{err}");
}

#[test]
fn a_delay_longer_than_the_record_is_refused() {
    let dir = scratch("fdr-short-record");
    let csv = dir.join("short.csv");
    let n = 50;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let q: Vec<f64> = t.iter().map(|t| (30.0 * t).sin() * 1e-3).collect();
    let u: Vec<f64> = t.iter().map(|t| (30.0 * t).cos()).collect();
    hd_io::write_columns(&csv, &["t", "qm", "qg", "vir"], &[t, q.clone(), q, u]).unwrap();
    let data = s(&repo_path("data/emps/DATA_EMPS.mat")).to_string();
    let text = emps(
        &[
            ("gain = \"gtau\"", "gain = 35.15"),
            ("kp = \"kp\"", "kp = 160.18"),
            ("kv = \"kv\"", "kv = 243.45"),
            ("delay = \"auto\"", "delay = 100"),
            ("disturbance = \"pulses_N\"", ""),
        ],
        "",
    )
    .replace(&format!("{data:?}"), &format!("{:?}", s(&csv)));
    refused("long-delay", &text, &["[controller] delay", "100 samples", "50 samples"]);
}

#[test]
fn parameters_of_another_law_are_named_with_their_law() {
    let text = emps(
        &[("friction = \"all\"", "friction = \"coulomb-viscous\"")],
        "[params]\nsigma0 = 1e5\n",
    );
    refused("other-law", &text, &["[params] sigma0", "belongs to the lugre"]);
}

#[test]
fn duplicate_experiment_names_are_refused() {
    let text = emps(&[], "");
    let exp = &text[text.find("[[experiment]]").unwrap()..text.find("[controller]").unwrap()];
    let doubled = text.replacen(exp, &format!("{exp}{exp}"), 1);
    refused("twice", &doubled, &["'estimation'", "used twice"]);
}

#[test]
fn configuration_and_record_paths_are_checked_by_type_and_size() {
    let dir = scratch("fdr-files");
    let out = dir.join("out");
    refused_at(
        Path::new("/dev/zero"),
        &out,
        &[],
        &["configuration /dev/zero", "not a regular file"],
    );
    refused_at(&dir, &out, &[], &["is a folder"]);
    let big = dir.join("big.toml");
    std::fs::write(&big, "# padding\n".repeat(500_000)).unwrap();
    refused_at(&big, &out, &[], &["big.toml", "bytes, more than the"]);
    let data = s(&repo_path("data/emps/DATA_EMPS.mat")).to_string();
    for (name, path, want) in
        [("zero", "/dev/zero", "not a regular file"), ("dir", s(&dir), "is a folder")]
    {
        let text = emps(&[], "").replace(&format!("{data:?}"), &format!("{path:?}"));
        refused(&format!("rec-{name}"), &text, &["[[experiment]] 'estimation'", want]);
    }
    let cfg = dir.join("ok.toml");
    std::fs::write(&cfg, emps(&[], "")).unwrap();
    refused_at(
        &cfg,
        &out,
        &["--validate", "/dev/zero"],
        &["--validate record /dev/zero", "not a regular file"],
    );
}

/// The shipped compliant configuration with its record in `dir` (a tiny hand-made CSV,
/// enough for the checks that come before the fit) and `extra` before `[[experiment]]`.
fn compliant(dir: &Path, extra: &str, current: f64) -> PathBuf {
    compliant_rows(dir, extra, current, 60)
}

/// [`compliant`] with a record of `n` rows.
fn compliant_rows(dir: &Path, extra: &str, current: f64, n: usize) -> PathBuf {
    let csv = dir.join("rec.csv");
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let wave = |a: f64| t.iter().map(|t| a * (40.0 * t).sin()).collect::<Vec<f64>>();
    let i: Vec<f64> = wave(1.0).iter().map(|v| current * v).collect();
    let cols = [t.clone(), wave(5.0), wave(1.0), wave(0.02), i];
    hd_io::write_columns(&csv, &["t", "u", "theta_m", "theta_l", "i"], &cols).unwrap();
    let start = repo_path("data/compliant/start.toml");
    let text = std::fs::read_to_string(repo_path("data/compliant/fit.toml"))
        .unwrap()
        .replace("\"start.toml\"", &format!("{:?}", s(&start)))
        .replace("\"../../out/compliant/chirp.csv\"", &format!("{:?}", s(&csv)))
        .replacen("[[experiment]]", &format!("{extra}\n[[experiment]]"), 1);
    let cfg = dir.join("c.toml");
    std::fs::write(&cfg, text).unwrap();
    cfg
}

#[test]
fn compliant_numbers_are_checked() {
    for (k, extra, needles) in [
        (0, "[params]\nJz = inf\n", &["c.toml, [params] Jz", "finite"][..]),
        (1, "[params]\nR = 0.0\n", &["[params] R", "> 0"]),
        (2, "[params]\nR = -1.0\n", &["[params] R"]),
        (3, "[params]\nR = nan\n", &["[params] R"]),
        (
            4,
            "[bounds]\nR = [1.0, 2.0]\n",
            &["[bounds] R", "excludes the start R = 7.5", "params file"],
        ),
    ] {
        let dir = scratch(&format!("fdr-compliant-{k}"));
        let cfg = compliant(&dir, extra, 1.0);
        refused_at(&cfg, &dir.join("out"), &[], needles);
    }
    let dir = scratch("fdr-compliant-substeps");
    let cfg = compliant(&dir, "", 1.0);
    let text = std::fs::read_to_string(&cfg).unwrap();
    std::fs::write(
        &cfg,
        text.replacen("voltage_between", "substeps = 1000000\nvoltage_between", 1),
    )
    .unwrap();
    refused_at(&cfg, &dir.join("out"), &[], &["c.toml, substeps", "10000"]);
}

/// A score rule that drops every sample (skip_first beyond the record) is refused: every
/// score was null and report.md read "NaN %".
#[test]
fn a_score_rule_that_leaves_nothing_to_score_is_refused() {
    let text = emps(&[("rule = \"emps\"", "skip_first = 30000")], "");
    refused("skip", &text, &["[score] skip_first", "24841"]);
}

/// A record of a few ticks is refused for its length, not blamed on the gear ratio (a
/// 12-row record was: "the load encoder moves 0.78 times the motor encoder divided by N").
#[test]
fn a_record_of_a_few_samples_is_refused_for_its_length() {
    let dir = scratch("fdr-short-record");
    let cfg = compliant_rows(&dir, "", 1.0, 12);
    let out = dir.join("out");
    let o = hdw(&["fit", "drive", "--config", s(&cfg), "--out", s(&out)]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let line = err.lines().find(|l| l.starts_with("error:")).unwrap_or("");
    assert!(line.contains("rec.csv: 12 samples") && line.contains("at least 50"), "{err}");
    assert!(!err.contains("gear ratio") && !out.join("fit.json").exists(), "{err}");
}

/// A position logged with the other sign than the command (position_scale = -1 on EMPS)
/// fails the controller check: said first, and the failed fit names it (it named no field).
#[test]
fn a_flipped_position_names_the_controller_check_and_the_scales() {
    let dir = scratch("fdr-flipped-position");
    let cfg = dir.join("flipped.toml");
    let text = emps(&[("disturbance = ", "position_scale = -1.0\ndisturbance = ")], "");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.join("out");
    let o = hdw(&["fit", "drive", "--config", s(&cfg), "--out", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    let first = err.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    assert!(first.starts_with("warning: The controller check fails"), "{err}");
    for needle in ["of the other sign", "position_scale and command_scale"] {
        assert!(first.contains(needle), "{first}");
    }
    if o.status.success() {
        let fit: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
        assert_eq!(fit["in_doubt"], true, "{fit}");
        assert_eq!(fit["laws"][0]["parameters"]["M"]["in_doubt"], true, "{fit}");
    } else {
        assert!(err.lines().any(|l| l.starts_with("error: The controller check fails")), "{err}");
    }
}

/// A transmission spelt otherwise is named, not the keys of the kind it meant.
#[test]
fn a_transmission_spelt_otherwise_is_named() {
    let dir = scratch("fdr-transmission");
    let cfg = compliant(&dir, "", 1.0);
    let text = std::fs::read_to_string(&cfg).unwrap();
    std::fs::write(&cfg, text.replacen("\"compliant\"", "\"Compliant\"", 1)).unwrap();
    refused_at(&cfg, &dir.join("out"), &[], &["c.toml, transmission: 'Compliant'", "lower case"]);
}

#[test]
fn a_dead_current_sensor_is_named() {
    let dir = scratch("fdr-dead-current");
    let cfg = compliant(&dir, "", 0.0);
    refused_at(&cfg, &dir.join("out"), &[], &["rec.csv", "column 'i' is constant", "dead sensor"]);
}

#[test]
fn a_params_file_that_is_no_params_file_is_refused() {
    let dir = scratch("fdr-params-file");
    let cfg = compliant(&dir, "", 1.0);
    let start = s(&repo_path("data/compliant/start.toml")).to_string();
    let text = std::fs::read_to_string(&cfg).unwrap();
    std::fs::write(&cfg, text.replace(&format!("{start:?}"), "\"/dev/zero\"")).unwrap();
    refused_at(&cfg, &dir.join("out"), &[], &["params file /dev/zero", "not a regular file"]);
    let big = dir.join("big.toml");
    std::fs::write(&big, "# padding\n".repeat(500_000)).unwrap();
    std::fs::write(&cfg, text.replace(&format!("{start:?}"), &format!("{:?}", s(&big)))).unwrap();
    refused_at(&cfg, &dir.join("out"), &[], &["big.toml", "bytes, more than the"]);
}

#[test]
fn a_second_fit_into_a_folder_in_use_is_refused() {
    let dir = scratch("fdr-lock");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    // A lock held by a live process of this host: this test's own.
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
    let lock = format!("pid = {}\nhost = \"{}\"\nstarted = 0\n", std::process::id(), host.trim());
    std::fs::write(out.join(".hdw-fit.lock"), lock).unwrap();
    let cfg = dir.join("ok.toml");
    std::fs::write(&cfg, emps(&[], "")).unwrap();
    refused_at(&cfg, &out, &[], &["a fit in this folder is running already"]);
    assert!(out.join(".hdw-fit.lock").exists());
}

#[test]
fn data_files_of_the_component_fits_are_checked_by_type() {
    let dir = scratch("fdr-fit-files");
    let o = hdw(&["fit", "hysteresis", "/dev/zero", "--out", s(&dir.join("h"))]);
    assert_one_line_error(&o, &["/dev/zero", "not a regular file"]);
    // A torque that never changes carries nothing to fit (was exit 0 with r2 = -4e24).
    let flat = dir.join("flat.csv");
    let rows: String = (0..200)
        .map(|k| format!("{},{},0.3\n", k as f64 * 1e-3, (k as f64 * 0.05).sin()))
        .collect();
    std::fs::write(&flat, format!("t,omega,torque\n{rows}")).unwrap();
    let o = hdw(&["fit", "friction", "--transient", s(&flat), "--out", s(&dir.join("f"))]);
    assert_one_line_error(&o, &["flat.csv", "column 'torque' is constant (0.3)"]);
    // A unit factor of 1e-300 made every torque 0 and a fit "determined" with SE 0.
    let data = repo_path("data/hysteresis-paper-range.csv");
    let o = hdw(&[
        "fit",
        "hysteresis",
        s(&data),
        "--torque-scale",
        "1e-300",
        "--out",
        s(&dir.join("s")),
    ]);
    assert_one_line_error(&o, &["--torque-scale 1e-300", "between 1e-12 and 1e12"]);
}

/// A fit into a folder holding an earlier fit leaves none of the earlier fit's outputs
/// that it does not write itself (here a plot of a law it does not fit).
#[test]
fn a_new_fit_replaces_the_earlier_fit_whole() {
    let dir = scratch("fdr-stale");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("fit.json"), "{}").unwrap();
    std::fs::write(out.join("validation-position.svg"), "<svg/>").unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let cfg = dir.join("cv.toml");
    let text = emps(&[("friction = \"all\"", "friction = \"coulomb-viscous\"")], "");
    std::fs::write(&cfg, text).unwrap();
    let o = fit_drive(&cfg, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.join("validation-position.svg").exists());
    assert!(out.join("notes.txt").exists() && out.join("fit.json").exists());
    assert!(!out.join(".hdw-fit.lock").exists());
}
