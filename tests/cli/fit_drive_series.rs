//! `hdw fit drive` writes the series behind its scores (series.parquet, read back here with
//! polars through hd-io) and a residual analysis whose verdict tells a true law from a
//! wrong one: a LuGre drive's loop recorded with white sensor noise is fitted with LuGre
//! (residuals white) and with Coulomb–viscous friction (model error named).

use crate::common::*;
use hd_ident::drive::{Controller, Experiment, FrictionLaw, simulate};
use hd_ident::synth::{Noise, add_noise};

/// The true drive: M, Fv, Fc, offset, Fs, vs, σ0, σ1, gain (a Stribeck hump 1.75 × Fc).
const TRUTH: [f64; 9] = [95.0, 200.0, 20.0, -3.0, 35.0, 0.01, 2.0e6, 500.0, 35.15];
/// Sensor noise on the logged position [m] and command [V].
const NOISE: (f64, f64) = (2.0e-6, 0.01);

/// Unit-variance Gaussian noise from `seed`.
fn white(n: usize, seed: u64) -> Vec<f64> {
    let mut v = vec![1.0; n];
    add_noise(&mut v, &Noise { relative: 1.0, seed });
    v.iter().map(|v| v - 1.0).collect()
}

/// 3 s at 1 kHz of the EMPS-like loop under a two-tone reference (reversals at low
/// speed, where the Stribeck hump acts), written as CSV with white noise on the logged
/// position and command.
fn write_record(path: &std::path::Path) {
    let n = 3000;
    let h = 1e-3;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
    let tau = std::f64::consts::TAU;
    let r: Vec<f64> =
        t.iter().map(|t| 0.02 * (tau * 0.5 * t).sin() + 0.01 * (tau * 1.3 * t).sin()).collect();
    let seed = Experiment::new("e", "made", t.clone(), r.clone(), r.clone(), vec![0.0; n], vec![])
        .unwrap();
    let c = Controller {
        kp: 160.18,
        kv: 243.45,
        saturation: 10.0,
        delay: 0,
        speed_filter: vec![0.5, 0.5],
        h,
        open_loop: None,
    };
    let s = simulate(FrictionLaw::LuGre, &TRUTH, &c, &seed);
    let (wq, wu) = (white(n, 1), white(n, 2));
    let q: Vec<f64> = s.position.iter().zip(&wq).map(|(q, w)| q + NOISE.0 * w).collect();
    let u: Vec<f64> = s.command.iter().zip(&wu).map(|(u, w)| u + NOISE.1 * w).collect();
    hd_io::write_columns(path, &["t", "q", "r", "u"], &[t, q, r, u]).unwrap();
}

/// A configuration of the record with `friction`, starting from the truth (the verdict,
/// not the optimiser's reach, is under test), scored without its first 10 samples.
fn config(dir: &std::path::Path, friction: &str) -> std::path::PathBuf {
    let names = FrictionLaw::LuGre.names();
    let params: String = names[..8]
        .iter()
        .zip(TRUTH)
        .filter(|(n, _)| friction == "lugre" || ["M", "Fv", "Fc", "offset"].contains(n))
        .map(|(n, v)| format!("{n} = {v}\n"))
        .collect();
    let text = format!(
        "axis = \"linear\"\nfriction = \"{friction}\"\ngain = 35.15\n\n[[experiment]]\nname = \"synthetic\"\nfile = \"record.csv\"\ntime = \"t\"\nposition = \"q\"\nreference = \"r\"\ncommand = \"u\"\n\n[controller]\nkp = 160.18\nkv = 243.45\nsaturation = 10.0\ndelay = 0\nspeed_filter = [0.5, 0.5]\n\n[start]\nmethod = \"values\"\n\n[params]\n{params}gain = 35.15\n\n[fit]\nnoise.force = {}\nnoise.position = {}\n\n[score]\nskip_first = 10\nmetric = \"rmse\"\n",
        35.15 * NOISE.1,
        NOISE.0
    );
    let path = dir.join(format!("{friction}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

fn fit(dir: &std::path::Path, friction: &str) -> (serde_json::Value, String, std::path::PathBuf) {
    let out = dir.join(format!("out-{friction}"));
    let cfg = config(dir, friction);
    hdw_ok(&["fit", "drive", "--config", cfg.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    (json(&out.join("fit.json")), report, out)
}

#[test]
fn residual_verdicts_tell_the_true_law_from_a_wrong_one_and_the_series_back_the_scores() {
    let dir = tempfile::tempdir().unwrap();
    write_record(&dir.path().join("record.csv"));

    // The true law: both outputs' residuals are the white sensor noise.
    let (j, report, out) = fit(dir.path(), "lugre");
    let rec = &j["residual_analysis"]["records"]["synthetic"];
    for o in ["force", "position"] {
        assert_eq!(rec[o]["white"], true, "{o}: {}", rec[o]["verdict"]);
        assert!(
            out.join(format!("resid-{o}.svg")).is_file()
                && out.join(format!("bode-{o}.svg")).is_file()
        );
    }
    assert!(report.contains("synthetic force: residuals white"), "{report}");
    assert!(report.contains("synthetic position: residuals white"), "{report}");

    // The series behind the scores, read back with polars: one row per output and sample,
    // the scored rows the rule's, and the scores recomputed from them.
    let t = hd_io::read_table(&out.join("series.parquet")).unwrap();
    assert_eq!(t.height, 2 * 3000);
    let output = t.text("output").unwrap();
    let (res, scored) = (t.num("residual").unwrap(), t.num("scored").unwrap());
    let rms = |all: bool| {
        let v: Vec<f64> = (0..t.height)
            .filter(|&k| output[k].as_deref() == Some("force") && (all || scored[k] == 1.0))
            .map(|k| res[k])
            .collect();
        ((v.iter().map(|x| x * x).sum::<f64>()) / v.len() as f64).sqrt()
    };
    let f = &j["experiments"]["synthetic"]["force"];
    assert_eq!((f["rule"].as_str(), f["samples"].as_u64()), (Some("custom"), Some(2990)));
    let (rule_rmse, all_rmse) =
        (f["rmse"].as_f64().unwrap(), f["all_samples"]["rmse"].as_f64().unwrap());
    assert!((rms(false) - rule_rmse).abs() < 1e-9 * rule_rmse, "{} vs {rule_rmse}", rms(false));
    assert!((rms(true) - all_rmse).abs() < 1e-9 * all_rmse, "{} vs {all_rmse}", rms(true));
    // The residual is the noise: the force's RMSE within 10 % of 35.15 × 0.01 N.
    assert!((rule_rmse / (35.15 * NOISE.1) - 1.0).abs() < 0.1, "{rule_rmse}");
    assert!(report.contains("custom: the first 10 samples dropped"), "{report}");

    // A wrong law: Coulomb–viscous friction leaves the Stribeck hump in the residuals.
    let (j, report, _) = fit(dir.path(), "coulomb-viscous");
    let rec = &j["residual_analysis"]["records"]["synthetic"];
    assert_eq!(rec["force"]["white"], false, "{}", rec["force"]["verdict"]);
    assert!(report.contains("synthetic force: model error left at lags 1–"), "{report}");
}
