//! `hdw fit drive` with `transmission = "compliant"` on a closed-loop record made by
//! `hdw synth drive --loop-kp …`: the controller check picks the delay, the loop is re-run
//! behind a current amplifier, the record names what it cannot separate; and the one-line
//! errors of bad closed-loop configurations.

use crate::common::{assert_one_line_error, fit_drive, hdw, json, ok, scratch, simulates};
use std::path::Path;

/// Motor parameters 20–30 % off, everything else the seed's (the truth of `synth drive`).
fn start(dir: &std::path::Path) {
    std::fs::write(
        dir.join("start.toml"),
        "R = 7.5\nKe = 0.4\nKm = 0.4\nJj = 8.5e-4\nCj = 0.0022\n",
    )
    .unwrap();
}

/// A closed-loop configuration; `controller` is the `[controller]` table's body, `fit`
/// the `[fit]` table's; `columns` replaces the experiment's input columns.
fn config(dir: &std::path::Path, columns: &str, controller: Option<&str>, fit: &str) -> String {
    let table = controller.map_or(String::new(), |c| format!("[controller]\n{c}\n"));
    let text = format!(
        "transmission = \"compliant\"\nparams_file = \"start.toml\"\n\n\
         [[experiment]]\nname = \"steps\"\nfile = \"loop.csv\"\ntime = \"t\"\n{columns}\n\
         motor = \"theta_m\"\nload = \"theta_l\"\ncurrent = \"i\"\n\n{table}\n[fit]\n{fit}\n"
    );
    let path = dir.join("fit.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

const LOOP_COLUMNS: &str = "reference = \"ref\"\ncommand = \"cmd\"";

#[test]
fn a_current_loop_is_fitted_back() {
    let dir = scratch("fit-compliant-loop");
    let rec = dir.join("loop.csv");
    crate::common::synth_loop(
        "--loop-kv 0.05 --loop-amplifier current --loop-delay 1 --freq 5 --t-end 0.6 \
         --motor-counts 65536",
        &rec,
    );
    start(&dir);
    let cfg = config(
        &dir,
        LOOP_COLUMNS,
        Some("kp = 30.0\nkv = 0.05\namplifier = \"current\""),
        "free = [\"R\", \"Ke\", \"Jj\", \"Cj\"]\nnoise = { motor = 2.77e-5, load = 1.73e-6 }",
    );
    let out = dir.join("out");
    ok(&fit_drive(Path::new(&cfg), &out));
    let doc = json(&out.join("fit.json"));
    // The check finds the delay the record was made with: the law one sample late
    // reproduces the command exactly.
    let c = &doc["controller"];
    assert_eq!(c["delay"], 1, "{c}");
    assert_eq!(c["delay_from"], "check");
    assert_eq!(c["amplifier"], "current");
    assert_eq!(c["position_unit"], "rad", "a rotary axis: the fed-back positions are in rad");
    assert_eq!(c["check"][1]["rms"].as_f64().unwrap(), 0.0, "{c}");
    assert!(c["check"][0]["percent"].as_f64().unwrap() > 1.0, "{c}");
    // Behind a current amplifier R acts on nothing: it is not fitted. The torque is Km × the
    // command, so Km (= Ke), Jj and Cj scale together, and the fit says so; each stays
    // within 3 standard errors of the truth at the start's Ke.
    assert_eq!(doc["parameters"]["R"]["free"], false);
    let said = doc["determination"].to_string();
    assert!(said.contains("Ke and Jj are not separable"), "{said}");
    for (name, truth) in [("Ke", 0.52), ("Jj", 6.8e-4), ("Cj", 0.003)] {
        let p = &doc["parameters"][name];
        let (v, se) = (p["value"].as_f64().unwrap(), p["std_error"].as_f64().unwrap());
        assert!((v - truth).abs() < 3.0 * se, "{name} = {v} ± {se}, truth {truth}");
    }
    for o in ["motor", "load", "command"] {
        let r = doc["experiments"]["steps"][o]["rmse_over_noise"].as_f64().unwrap();
        assert!(r < 1.2, "{o}: {r}");
    }
    assert_eq!(doc["experiments"]["steps"]["command"]["unit"], "A");
    // The ideal amplifier's current is its command: compared once, as the command.
    assert!(doc["experiments"]["steps"].get("current").is_none());
    assert!(out.join("command.svg").exists());
    // params.toml is a params file the simulator runs.
    simulates(&out, &dir.join("sim"));
}

#[test]
fn bad_closed_loop_configurations_get_one_line_errors() {
    let dir = scratch("fit-compliant-loop-bad");
    let rec = dir.join("loop.csv");
    crate::common::synth_loop("--loop-kv 0.5 --t-end 0.05", &rec);
    start(&dir);
    let good = "kp = 30.0\nkv = 0.5";
    let cases: [(&str, Option<&str>, &str, &[&str]); 9] = [
        // A reference without a controller, a controller without a reference.
        (
            "reference = \"ref\"\nvoltage = \"cmd\"",
            None,
            "",
            &["'steps' reference", "[controller]"],
        ),
        ("command = \"cmd\"", Some(good), "", &["'steps' reference", "missing"]),
        (
            LOOP_COLUMNS,
            Some("kp = 30.0\nkv = 0.5\nfeedback = \"encoder\""),
            "",
            &["[controller] feedback", "encoder"],
        ),
        (
            LOOP_COLUMNS,
            Some("kp = 30.0\nkv = 0.5\namplifier = \"torque\""),
            "",
            &["[controller] amplifier", "torque"],
        ),
        (LOOP_COLUMNS, Some("kp = 30.0"), "", &["[controller] kv", "missing"]),
        (LOOP_COLUMNS, Some("kp = 30.0\nkv = 0.5\np = 2.0\nd = 0.1"), "", &["[controller] p"]),
        (
            "reference = \"ref\"\ncommand = \"cmd\"\nvoltage = \"cmd\"",
            Some(good),
            "",
            &["'steps' voltage", "command"],
        ),
        (
            "voltage = \"cmd\"",
            None,
            "outputs = [\"motor\", \"command\"]",
            &["[fit] outputs", "[controller]"],
        ),
        (
            LOOP_COLUMNS,
            Some("kp = 30.0\nkv = 0.5\nspeed_filter = [0.5, 0.4]"),
            "",
            &["[controller] speed_filter"],
        ),
    ];
    for (columns, controller, fit, expect) in cases {
        let cfg = config(&dir, columns, controller, fit);
        let out = dir.join("out");
        let o = fit_drive(Path::new(&cfg), &out);
        let mut needles = expect.to_vec();
        needles.push("fit.toml");
        assert_one_line_error(&o, &needles);
        assert!(!out.exists(), "a failed fit leaves no output folder");
    }
    // A missing reference column names the file and the column.
    let cfg = config(&dir, "reference = \"setpoint\"\ncommand = \"cmd\"", Some(good), "");
    let o = fit_drive(Path::new(&cfg), &dir.join("out"));
    assert_one_line_error(&o, &["setpoint", "loop.csv"]);
    // Closed-loop options of `synth drive` are checked too.
    let o = hdw(&[
        "synth",
        "drive",
        "--loop-kp",
        "30",
        "--loop-kv",
        "0.5",
        "--loop-feedback",
        "tacho",
        "--out",
        dir.join("x.csv").to_str().unwrap(),
    ]);
    assert_one_line_error(&o, &["--loop-feedback", "tacho"]);
}
