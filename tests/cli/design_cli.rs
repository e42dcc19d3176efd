//! `hdw design`: a small design from a params file respects its limits and writes its
//! outputs; the refit check runs; a missing drive is refused in one line.

use crate::common::{hdw, hdw_ok, json, repo_path, scratch};
use std::path::PathBuf;

/// `hdw design --params data/compliant/start.toml ARGS --out <scratch NAME>` (ARGS split at
/// whitespace): the output folder and its design.json.
fn design_from_start(name: &str, args: &str) -> (PathBuf, serde_json::Value) {
    let out = scratch(name);
    let params = repo_path("data/compliant/start.toml");
    let mut all = vec!["design", "--params", params.to_str().unwrap()];
    all.extend(args.split_whitespace());
    all.extend_from_slice(&["--out", out.to_str().unwrap()]);
    hdw_ok(&all);
    let d = json(&out.join("design.json"));
    (out, d)
}

#[test]
fn design_from_params_meets_its_limits_and_writes_outputs() {
    let (out, d) = design_from_start(
        "design-params",
        "--free R,Ke,Jj,Cj --duration 0.2 --evaluations 8 --family chirp,ramp \
         --voltage 6 --speed 3",
    );
    for f in [
        "input.csv",
        "input.parquet",
        "design.json",
        "report.md",
        "input.svg",
        "spectrum.svg",
        "response.svg",
        "se.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert_eq!(d["criterion"], "D-optimal");
    let peaks = d["design"]["peaks"].as_array().unwrap();
    for p in peaks {
        let (pk, lim) = (p["peak"].as_f64().unwrap(), p["limit"].as_f64().unwrap());
        assert!(pk <= lim * (1.0 + 1e-9), "{p}");
    }
    // The speed limit is the one that binds at 6 V (the motor reaches ~11 rad/s at 6 V).
    assert_eq!(d["design"]["binds"], "speed", "{}", d["design"]);
    let text = std::fs::read_to_string(out.join("input.csv")).unwrap();
    let umax = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max);
    assert!(umax <= 6.0 + 1e-9 && umax > 0.0);
    for k in ["R", "Ke", "Jj", "Cj"] {
        assert!(d["parameters"][k]["design_alone_std_error"].as_f64().unwrap() > 0.0, "{k}");
    }
}

#[test]
fn design_check_refits() {
    let (_, d) = design_from_start(
        "design-check",
        "--free R,Ke,Cj --duration 0.2 --evaluations 4 --family chirp --check 3",
    );
    assert_eq!(d["check"]["refits"], 3, "{}", d["check"]);
    // Each refit's verdict in words, and per parameter its estimates, SEs and verdicts.
    assert_eq!(d["check"]["verdicts"].as_array().unwrap().len(), 3);
    for (k, p) in d["check"]["parameters"].as_object().unwrap() {
        for field in ["estimates", "std_errors", "determined"] {
            assert_eq!(p[field].as_array().unwrap().len(), 3, "{k} {field}");
        }
        let det = p["determined"].as_array().unwrap().iter().filter(|b| b == &true).count();
        assert_eq!(p["determined_in"], det, "{k}");
        let no_se = p["std_errors"].as_array().unwrap().iter().filter(|s| s.is_null()).count();
        assert_eq!(p["without_std_error_in"], no_se, "{k}");
    }
    // Each refit's cost against the truth's on its own records: the truth is a point the
    // fit could reach, so a refit at its optimum is at or below it (these three are).
    let above = d["check"]["cost_above_truth"].as_array().unwrap();
    assert_eq!(above.len(), 3, "{}", d["check"]);
    for a in above {
        assert!(a.as_f64().unwrap() < 0.5, "a refit stopped above the truth's cost: {a}");
    }
    assert_eq!(d["check"]["short_of_optimum"], 0);
    let r = &d["check"]["parameters"]["R"];
    // Three refits of R (truth 7.5 in the start file) land near the truth.
    assert!((r["mean"].as_f64().unwrap() / 7.5 - 1.0).abs() < 0.01, "{r}");
}

#[test]
fn design_without_a_drive_is_refused() {
    let out = scratch("design-none");
    let o = hdw(&["design", "--out", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--fit DIR") && err.contains("--params"), "{err}");
}

/// Limits and sensors no rig has are refused before any work, naming the option (a limit
/// of 1e-300 V ended in a plotting error and left a half-written folder; a motor encoder of
/// 0 counts was dropped silently; a negative current noise was recorded as given).
#[test]
fn limits_no_rig_has_are_refused_naming_the_option() {
    let out = scratch("design-limits");
    let params = repo_path("data/compliant/start.toml");
    for (args, needle) in [
        (&["--voltage", "1e-300"][..], "--voltage 1e-300"),
        (&["--voltage", "1e300"][..], "--voltage 1e300"),
        (&["--current", "1e-300"][..], "--current 1e-300"),
        (&["--deflection", "1e-300"][..], "--deflection 1e-300"),
        (&["--motor-counts", "0"][..], "--motor-counts 0"),
        (&["--current-noise", "-1"][..], "--current-noise -1"),
        (&["--current-noise", "0"][..], "--current-noise 0"),
        (&["--torque", "0"][..], "--torque 0"),
        (&["--load-angle", "-0.1"][..], "--load-angle -0.1"),
        (&["--load-angle", "1e-300"][..], "--load-angle 1e-300"),
    ] {
        let mut a = vec!["design", "--params", params.to_str().unwrap(), "--free", "R,Ke"];
        a.extend(args);
        a.extend(["--out", out.to_str().unwrap()]);
        crate::common::assert_one_line_error(&hdw(&a), &[needle, "expected"]);
        assert!(!out.join("design.json").exists(), "{needle}");
    }
}

/// A tight range of travel is the limit that binds: every designed input keeps the load
/// within it, and design.json reports the peak excursion and the transmitted torque.
#[test]
fn a_short_range_of_travel_binds() {
    let (_, d) = design_from_start(
        "design-travel",
        "--free R,Ke,Jj,Cj --duration 0.2 --evaluations 6 --family chirp,ramp --load-angle 5e-4",
    );
    assert_eq!(d["design"]["binds"], "load angle", "{}", d["design"]);
    let peaks = d["design"]["peaks"].as_array().unwrap();
    let travel = peaks.iter().find(|p| p["quantity"] == "load angle").expect("load angle peak");
    let peak = travel["peak"].as_f64().unwrap();
    // Binding: the peak sits just under the limit (each rescaling aims 0.5 % below it; the
    // response is nonlinear in the amplitude, so allow a few per cent).
    assert!(peak <= 5e-4 * (1.0 + 1e-9) && peak > 5e-4 * 0.9, "{travel}");
    assert!(d["design"]["amplitude_V"].as_f64().unwrap() < 12.0, "{}", d["design"]);
    assert_eq!(d["limits"]["load_angle_rad"], 5e-4, "{}", d["limits"]);
    assert!(d["design"]["peak_torque_Nm"].as_f64().unwrap() > 0.0, "{}", d["design"]);
}

/// In closed loop (`--controller`), the design is of the position reference: input.csv holds
/// the `reference` column [rad], within `--reference`; design.json names the loop and
/// keeps every simulated peak within its limit.
#[test]
fn a_closed_loop_design_is_of_the_reference() {
    // The shipped controller with a saturation and a delay (the file's are 0 and none).
    let ctl = scratch("design-loop-ctl").join("controller.toml");
    std::fs::create_dir_all(ctl.parent().unwrap()).unwrap();
    let text = std::fs::read_to_string(repo_path("data/compliant/controller.toml")).unwrap();
    let text = text.replace("delay = 0 ", "delay = 2 ") + "saturation = 10.0\n";
    std::fs::write(&ctl, text).unwrap();
    let (out, d) = design_from_start(
        "design-loop",
        &format!(
            "--controller {} --reference 0.5 --free R,Ke,Jj,Cj --duration 0.2 --evaluations 4 \
             --family chirp,ramp --voltage 6",
            ctl.display()
        ),
    );
    assert_eq!(d["input_column"], "reference", "{}", d["input_column"]);
    assert_eq!(d["input_unit"], "rad");
    assert_eq!(d["controller"]["kp"], 30.0, "{}", d["controller"]);
    assert_eq!(d["controller"]["delay"], 2, "{}", d["controller"]);
    assert_eq!(d["controller"]["saturation"], 10.0, "{}", d["controller"]);
    assert!(d["controller"]["command_noise"].as_f64().unwrap() > 0.0, "{}", d["controller"]);
    assert_eq!(d["limits"]["reference_rad"], 0.5);
    for p in d["design"]["peaks"].as_array().unwrap() {
        let (pk, lim) = (p["peak"].as_f64().unwrap(), p["limit"].as_f64().unwrap());
        assert!(pk <= lim * (1.0 + 1e-9), "{p}");
    }
    let text = std::fs::read_to_string(out.join("input.csv")).unwrap();
    assert!(text.lines().next().unwrap().contains("reference"), "{}", text.lines().next().unwrap());
    let rmax = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap().abs())
        .fold(0.0, f64::max);
    assert!(rmax > 0.0 && rmax <= 0.5 * (1.0 + 1e-9), "peak reference {rmax}");
    // It fades in and out: no step into the loop at either end.
    let rows: Vec<&str> = text.lines().skip(1).collect();
    for row in [rows[0], rows[rows.len() - 1]] {
        assert_eq!(row.split(',').nth(1).unwrap().parse::<f64>().unwrap(), 0.0, "{row}");
    }
    assert!(d["design"]["amplitude_rad"].as_f64().unwrap() <= 0.5 * (1.0 + 1e-9));
    for k in ["R", "Ke", "Jj", "Cj"] {
        assert!(d["parameters"][k]["design_alone_std_error"].as_f64().unwrap() > 0.0, "{k}");
    }
}

/// A reference without a loop, a loop without a reference and a controller file without
/// its table are refused in one line naming what is missing.
#[test]
fn a_loop_needs_both_its_controller_and_its_reference() {
    let out = scratch("design-loop-refused");
    let params = repo_path("data/compliant/start.toml");
    let ctl = repo_path("data/compliant/controller.toml");
    let no_table = repo_path("data/compliant/start.toml");
    for (args, needles) in [
        (vec!["--reference", "0.5"], &["--reference", "needs a loop"][..]),
        (vec!["--controller", ctl.to_str().unwrap()], &["--reference", "closed-loop"][..]),
        (
            vec!["--controller", no_table.to_str().unwrap(), "--reference", "1"],
            &["[controller]"][..],
        ),
    ] {
        let mut a = vec!["design", "--params", params.to_str().unwrap(), "--free", "R,Ke"];
        a.extend(args);
        a.extend(["--out", out.to_str().unwrap()]);
        crate::common::assert_one_line_error(&hdw(&a), needles);
        assert!(!out.join("design.json").exists(), "{needles:?}");
    }
}

/// `--fit` of a closed-loop fit brings its loop (the controller and the delay its check
/// chose), and finds the fit's configuration from any working folder: fit.json keeps its
/// absolute path besides the one the fit was given (a relative path, which from elsewhere
/// named nothing).
#[test]
fn a_loop_fit_designs_its_reference_from_another_folder() {
    let dir = scratch("design-loop-fit");
    let cfg_dir = dir.join("cfg");
    std::fs::create_dir_all(&cfg_dir).unwrap();
    let steps = cfg_dir.join("steps.csv");
    crate::common::synth_loop(
        "--loop-kv 0.5 --loop-reference steps --freq 5 --t-end 0.5 --motor-counts 65536",
        &steps,
    );
    let start = repo_path("data/compliant/start.toml");
    let text = std::fs::read_to_string(repo_path("data/compliant/loop.toml"))
        .unwrap()
        .replace("\"start.toml\"", &format!("{:?}", start.to_str().unwrap()))
        .replace("\"../../out/compliant/loop-steps.csv\"", "\"steps.csv\"");
    std::fs::write(cfg_dir.join("loop.toml"), text).unwrap();
    let fit = dir.join("out").join("fit");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_hdw"))
        .current_dir(&cfg_dir)
        .args(["fit", "drive", "--config", "loop.toml", "--out", fit.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // From the test's own folder, where "loop.toml" names nothing.
    let out = dir.join("design");
    hdw_ok(&[
        "design",
        "--fit",
        fit.to_str().unwrap(),
        "--duration",
        "0.2",
        "--evaluations",
        "3",
        "--family",
        "chirp",
        "--out",
        out.to_str().unwrap(),
    ]);
    let d = json(&out.join("design.json"));
    let f = json(&fit.join("fit.json"));
    assert_eq!(d["input_column"], "reference");
    assert_eq!(d["controller"]["kp"], 30.0);
    assert_eq!(d["controller"]["delay"], f["controller"]["delay"], "{}", d["controller"]);
    // The command's noise is the fit's estimate for its record.
    assert_eq!(d["controller"]["command_noise"], f["experiments"]["steps"]["command"]["noise"]);
    let peak_ref = d["limits"]["reference_rad"].as_f64().unwrap();
    assert!(peak_ref > 0.0 && d["design"]["peak_reference_rad"].as_f64().unwrap() <= peak_ref);
}

/// The spectrum family beside the chirp: it is searched, its input meets the limits, and it
/// does no worse than the chirp it may weigh in (the chirp's best is one of its elements).
#[test]
fn the_spectrum_family_weighs_the_chirp_in() {
    let (_, d) = design_from_start(
        "design-spectrum",
        "--free R,Ke,Jj,Cj --duration 0.2 --evaluations 6 --family chirp,spectrum --voltage 6",
    );
    let searched = d["searched"].as_array().unwrap();
    let cost = |name: &str| {
        searched.iter().find(|s| s["family"] == name).unwrap()["criterion"].as_f64().unwrap()
    };
    assert!(cost("spectrum") <= cost("chirp"), "{searched:?}");
    for p in d["design"]["peaks"].as_array().unwrap() {
        let (pk, lim) = (p["peak"].as_f64().unwrap(), p["limit"].as_f64().unwrap());
        assert!(pk <= lim * (1.0 + 1e-9), "{p}");
    }
}
