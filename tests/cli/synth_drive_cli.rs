//! `hdw synth drive`: the drive under a voltage test, logged with quantised encoders and a
//! noisy current.

use crate::common::{assert_one_line_error, hdw, hdw_ok, scratch};
use std::f64::consts::TAU;

fn columns(path: &std::path::Path) -> Vec<Vec<f64>> {
    let names = ["t", "u", "i", "theta_m", "theta_l", "theta_j_true", "theta_z_true"];
    hd_io::read_columns(path, &names).unwrap()
}

#[test]
fn encoders_are_quantised_and_the_current_carries_the_asked_noise() {
    let dir = scratch("synth-drive");
    let (noisy, clean) = (dir.join("noisy.csv"), dir.join("clean.csv"));
    let base = ["synth", "drive", "--input", "multisine", "--voltage", "10", "--t-end", "0.5"];
    let run = |out: &std::path::Path, extra: &[&str]| {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        hdw_ok(&args);
        columns(out)
    };
    let c = run(&noisy, &["--current-noise", "0.02"]);
    let z = run(&clean, &["--current-noise", "0"]);
    assert_eq!(c[0].len(), 501, "0.5 s logged every 1 ms");
    // The multisine's peak is the asked voltage; the log, every 1 ms, may step over it.
    let peak = c[1].iter().fold(0.0f64, |p, v| p.max(v.abs()));
    assert!(peak <= 10.0 + 1e-9 && peak > 9.5, "{peak}");
    // Each encoder reads its true angle to within half a count, on whole counts.
    for (meas, truth, counts) in [(3, 5, 4096.0), (4, 6, 1048576.0)] {
        let q = TAU / counts;
        for (m, t) in c[meas].iter().zip(&c[truth]) {
            assert!((m - t).abs() <= 0.5 * q * (1.0 + 1e-9), "{m} vs {t}");
            let k = m / q;
            assert!((k - k.round()).abs() < 1e-6, "{m} is not a whole number of counts");
        }
    }
    // The motor moves by many counts: the test excites it.
    let span =
        c[3].iter().fold(f64::MIN, |a, &b| a.max(b)) - c[3].iter().fold(f64::MAX, |a, &b| a.min(b));
    assert!(span > 50.0 * TAU / 4096.0, "{span}");
    // The current's noise: its size relative to the clean current's RMS.
    let n = z[2].len() as f64;
    let rms = (z[2].iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    let sd = (c[2].iter().zip(&z[2]).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / n).sqrt();
    assert!((sd / rms - 0.02).abs() < 0.002, "noise {:.4} of the RMS", sd / rms);
    // Everything else is the same run.
    assert_eq!(c[5], z[5]);
}

#[test]
fn bad_tests_are_refused_in_one_line() {
    let dir = scratch("synth-drive-bad");
    let out = dir.join("x.csv");
    let o = out.to_str().unwrap();
    let r = hdw(&["synth", "drive", "--input", "square", "--out", o]);
    assert_one_line_error(&r, &["--input square", "chirp or multisine"]);
    let r = hdw(&["synth", "drive", "--sample-period", "0", "--out", o]);
    assert_one_line_error(&r, &["--sample-period"]);
    let r = hdw(&["synth", "drive", "--t-end", "1e9", "--out", o]);
    assert_one_line_error(&r, &["--t-end 1000000000", "samples"]);
    let r = hdw(&["synth", "drive", "--applied", "smooth", "--out", o]);
    assert_one_line_error(&r, &["--applied smooth", "held or continuous"]);
    assert!(!out.exists());
}

/// Held (the default) and continuous application log the same voltage samples; the drive
/// answers differently between them, by a little: the held staircase lags the signal by
/// half a sample.
#[test]
fn a_held_voltage_logs_the_same_samples_as_the_continuous_one() {
    let dir = scratch("synth-drive-held");
    let (held, cont) = (dir.join("held.csv"), dir.join("cont.csv"));
    let base = ["synth", "drive", "--input", "chirp", "--freq", "5", "--t-end", "0.5"];
    for (path, how) in [(&held, "held"), (&cont, "continuous")] {
        let mut args = base.to_vec();
        args.extend_from_slice(&["--applied", how, "--out", path.to_str().unwrap()]);
        hdw_ok(&args);
    }
    let (h, c) = (columns(&held), columns(&cont));
    for (a, b) in h[1].iter().zip(&c[1]) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + b.abs()), "{a} vs {b}");
    }
    let span = c[5].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = h[5].iter().zip(&c[5]).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(diff > 0.0 && diff < 0.05 * span, "held and continuous differ by {diff} of {span}");
}

/// Options that would give a useless, absurd or endless record are refused before any
/// work, each naming the option at fault; nothing is written.
#[test]
fn unusable_records_are_refused_naming_the_option() {
    let dir = scratch("synth-drive-refused");
    let out = dir.join("x.csv");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        // Two rows (t = 0 and t = 2) are no record.
        (
            &["--sample-period", "10"],
            &["--sample-period 10 s", "0.2 sample intervals", "50 samples"],
        ),
        (
            &["--t-end", "0.04"],
            &[
                "--sample-period 0.001",
                "40 sample intervals",
                "use --sample-period 0.00081 s or less",
            ],
        ),
        // The band 600-60000 Hz against the 500 Hz Nyquist frequency of a 1 ms log.
        (&["--freq", "6000"], &["--freq 6000 Hz", "wholly above the Nyquist frequency 500 Hz"]),
        (&["--voltage", "1e308"], &["--voltage 1e308", "at most 1e4 V"]),
        (&["--voltage", "0"], &["--voltage 0", "not zero"]),
        (&["--voltage", "nan"], &["--voltage NaN"]),
        // 20 000 s at 1 ms: 20 M samples, once 25 minutes and 3.3 GB without a word.
        (&["--t-end", "20000"], &["--t-end 20000", "2.000e7 samples", "1e7"]),
        (
            &[
                "--input",
                "multisine",
                "--freq",
                "4000",
                "--sample-period",
                "1e-4",
                "--t-end",
                "100",
            ],
            &["--input multisine", "--freq 4000", "profile points"],
        ),
    ];
    let loop_cases: &[(&[&str], &[&str])] = &[
        (&["--loop-amplitude", "1e308"], &["--loop-amplitude 1e308", "at most 1e4 rad"]),
        (&["--loop-amplitude", "0"], &["--loop-amplitude 0", "not zero"]),
        (
            &["--loop-amplitude", "100", "--loop-reference", "chirp"],
            &["--loop-amplitude 100", "--freq 20", "rad/s"],
        ),
        (&["--loop-delay", "1000000000"], &["--loop-delay 1000000000", "half the record"]),
        (&["--loop-delay", "1001"], &["--loop-delay 1001 samples (1.001 s)", "2001 samples"]),
        (&["--loop-kv", "-0.5"], &["--loop-kv -0.5", "gain > 0"]),
        (&["--loop-kp", "0"], &["--loop-kp 0", "gain > 0"]),
        (&["--loop-reference", "ramp"], &["--loop-reference ramp", "steps or chirp"]),
    ];
    let run = |extra: &[&str]| {
        let mut args = vec!["synth", "drive"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", o]);
        let start = std::time::Instant::now();
        let r = hdw(&args);
        assert!(start.elapsed().as_secs_f64() < 10.0, "{extra:?} took long");
        r
    };
    for (extra, needles) in cases {
        assert_one_line_error(&run(extra), needles);
    }
    for (extra, needles) in loop_cases {
        let mut args = vec!["--t-end", "2"];
        for (gain, value) in [("--loop-kp", "30"), ("--loop-kv", "0.5")] {
            if !extra.contains(&gain) {
                args.extend_from_slice(&[gain, value]);
            }
        }
        args.extend_from_slice(extra);
        assert_one_line_error(&run(&args), needles);
    }
    assert!(!out.exists());
}

/// A band that only reaches past the Nyquist frequency is recorded, with a warning.
#[test]
fn a_band_reaching_past_nyquist_is_a_warning() {
    let dir = scratch("synth-drive-alias");
    let out = dir.join("a.csv");
    let args =
        ["synth", "drive", "--freq", "100", "--t-end", "0.2", "--out", out.to_str().unwrap()];
    let r = hdw_ok(&args);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(err.contains("warning: --freq 100 Hz: the band reaches 1000 Hz"), "{err}");
    assert_eq!(columns(&out)[0].len(), 201);
}
