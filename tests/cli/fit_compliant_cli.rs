//! `hdw fit drive` with `transmission = "compliant"`: a voltage test of the simulator's drive
//! fitted back (motor parameters free, the rest at the truth), its outputs, the params file
//! `hdw simulate` runs, and the one-line errors of bad configurations.

use crate::common::{assert_one_line_error, fit_drive, hdw_ok, json, ok, scratch, simulates};

/// The configuration of the tests, with `extra` appended to its top level and `fit` as its
/// `[fit]` table.
fn config(dir: &std::path::Path, extra: &str, fit: &str) -> std::path::PathBuf {
    let text = format!(
        "transmission = \"compliant\"\nparams_file = \"start.toml\"\n{extra}\n\
         [[experiment]]\nname = \"chirp\"\nfile = \"chirp.csv\"\ntime = \"t\"\nvoltage = \"u\"\n\
         motor = \"theta_m\"\nload = \"theta_l\"\ncurrent = \"i\"\n\n[fit]\n{fit}\n"
    );
    let path = dir.join("fit.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The `[fit]` table of the tests that fit the motor: its four parameters free, the
/// encoders' noise one count/√12 (4096 and 2^20 counts per turn).
const MOTOR_FIT: &str =
    "free = [\"R\", \"Ke\", \"Jj\", \"Cj\"]\nnoise = { motor = 4.43e-4, load = 1.73e-6 }";

/// The motor's parameters 20–30 % off the seed's, as params-file lines.
const MOTOR_START: &str = "R = 7.5\nKe = 0.4\nKm = 0.4\nJj = 8.5e-4\nCj = 0.0022\n";

/// Motor parameters 20–30 % off, everything else the seed's (the truth of `synth drive`).
fn start(dir: &std::path::Path) {
    std::fs::write(dir.join("start.toml"), MOTOR_START).unwrap();
}

/// The drive of params-file lines `truth` recorded by `hdw synth drive` (5 Hz centre, 1 s)
/// in scratch folder `name`, fitted from the lines `start` with the motor's 20–30 % off
/// ([`MOTOR_START`]) and `[fit]` table `fit`: the fit must succeed with every output at
/// the noise (≤ 1.2×), and `hdw simulate` must run its params.toml. Returns fit.json and
/// params.toml's text.
fn fitted_back(name: &str, truth: &str, start: &str, fit: &str) -> (serde_json::Value, String) {
    let dir = scratch(name);
    let rec = dir.join("chirp.csv");
    let truth_file = dir.join("truth.toml");
    std::fs::write(&truth_file, truth).unwrap();
    let synth = ["synth", "drive", "--params", truth_file.to_str().unwrap(), "--freq", "5"];
    let mut synth = synth.to_vec();
    synth.extend(["--t-end", "1", "--out", rec.to_str().unwrap()]);
    hdw_ok(&synth);
    std::fs::write(dir.join("start.toml"), format!("{start}{MOTOR_START}")).unwrap();
    let cfg = config(&dir, "", fit);
    let out = dir.join("out");
    ok(&fit_drive(&cfg, &out));
    let doc = json(&out.join("fit.json"));
    for o in ["motor", "load", "current"] {
        let r = doc["experiments"]["chirp"][o]["rmse_over_noise"].as_f64().unwrap();
        assert!(r < 1.2, "{name}, {o}: {r}");
    }
    simulates(&out, &dir.join("sim"));
    (doc, std::fs::read_to_string(out.join("params.toml")).unwrap())
}

/// A scratch folder `name` holding a `hdw synth drive` record of the seed drive (5 Hz centre,
/// `t_end` seconds) as chirp.csv and the start values of [`start`].
fn recorded(name: &str, t_end: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    let rec = dir.join("chirp.csv");
    hdw_ok(&["synth", "drive", "--freq", "5", "--t-end", t_end, "--out", rec.to_str().unwrap()]);
    start(&dir);
    dir
}

#[test]
fn the_motor_is_fitted_back_from_a_voltage_test() {
    let dir = recorded("fit-compliant", "2");
    let cfg = config(&dir, "", MOTOR_FIT);
    let out = dir.join("out");
    ok(&fit_drive(&cfg, &out));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    assert_eq!(doc["transmission"], "compliant");
    // The truth is the seed drive: the motor's parameters come back within 3 standard
    // errors; R and Jj are determined, Ke and Cj only together on this chirp (back-EMF and
    // viscous damping both brake the speed), which the fit says; Km follows Ke.
    for (name, truth, determined) in
        [("R", 6.0, true), ("Jj", 6.8e-4, true), ("Ke", 0.52, false), ("Cj", 0.003, false)]
    {
        let p = &doc["parameters"][name];
        let (v, se) = (p["value"].as_f64().unwrap(), p["std_error"].as_f64().unwrap());
        assert_eq!(p["determined"].as_bool().unwrap(), determined, "{name}: {p}");
        assert!((v - truth).abs() < 3.0 * se, "{name} = {v} ± {se}, truth {truth}");
    }
    let said = doc["determination"].to_string();
    assert!(said.contains("Ke and Cj are not separable"), "{said}");
    assert_eq!(doc["parameters"]["Km"]["value"], doc["parameters"]["Ke"]["value"]);
    // At the noise: each output's RMS residual within 1.2 times its noise level.
    for o in ["motor", "load", "current"] {
        let r = doc["experiments"]["chirp"][o]["rmse_over_noise"].as_f64().unwrap();
        assert!(r < 1.2, "{o}: {r}");
    }
    for f in ["params.toml", "report.md", "motor.svg", "residuals-load.svg", "current.svg"] {
        assert!(out.join(f).exists(), "{f}");
    }
    // Without the current the motor encoder sees only two combinations of R, Ke, Jj and
    // Cj: one member is held, and the encoders are still fitted to their noise.
    let text = std::fs::read_to_string(&cfg).unwrap().replace("current = \"i\"\n", "");
    std::fs::write(&cfg, text).unwrap();
    let bare = dir.join("bare");
    ok(&fit_drive(&cfg, &bare));
    let doc2 = json(&bare.join("fit.json"));
    for o in ["motor", "load"] {
        let r = doc2["experiments"]["chirp"][o]["rmse_over_noise"].as_f64().unwrap();
        assert!(r < 1.2, "without the current, {o}: {r}");
    }
    let held =
        ["R", "Ke", "Jj", "Cj"].iter().filter(|n| doc2["parameters"][**n]["held"] == true).count();
    assert_eq!(held, 1, "{}", doc2["determination"]);
    // params.toml is a params file the simulator runs.
    simulates(&out, &dir.join("sim"));
}

/// Drives whose gear is a Bouc–Wen element or Maxwell-slip elements (`stiffness = "…"` in
/// the params file, `hdw synth drive --stiffness …` for the record): the fit runs that law,
/// so the residuals sit at the noise only with it; fit.json and params.toml name the law
/// and carry its parameters (not the memory's), and the simulator runs the params file.
/// Naming the memory's parameters for such a drive is an error. The same for friction
/// levels that differ by direction (Tc_neg, Ts_neg in the params file).
#[test]
fn other_gear_laws_are_fitted_and_written_back() {
    let directional: &[&str] = &["--set", "Tc_neg=0.1", "--set", "Ts_neg=0.18"];
    for (law, own, set, lines) in [
        ("bouc-wen", "bw_beta", &[][..], ""),
        ("maxwell-slip", "ms_delta", &[][..], ""),
        ("memory", "Ts_neg", directional, "Tc_neg = 0.1\nTs_neg = 0.18\n"),
    ] {
        let dir = scratch(&format!("fit-compliant-{law}"));
        let rec = dir.join("chirp.csv");
        let mut synth =
            vec!["synth", "drive", "--stiffness", law, "--freq", "5", "--t-end", "1", "--out"];
        synth.push(rec.to_str().unwrap());
        synth.extend(set);
        hdw_ok(&synth);
        std::fs::write(
            dir.join("start.toml"),
            format!(
                "stiffness = \"{law}\"\nR = 7.5\nKe = 0.4\nKm = 0.4\nJj = 8.5e-4\nCj = 0.0022\n{lines}"
            ),
        )
        .unwrap();
        let cfg = config(&dir, "", MOTOR_FIT);
        let out = dir.join("out");
        ok(&fit_drive(&cfg, &out));
        let doc = json(&out.join("fit.json"));
        assert_eq!(doc["stiffness"], law);
        assert!(doc["parameters"][own].is_object());
        assert_eq!(doc["parameters"]["mem_A"].is_null(), law != "memory");
        assert_eq!(doc["directional_friction"], !lines.is_empty());
        for o in ["motor", "load", "current"] {
            let r = doc["experiments"]["chirp"][o]["rmse_over_noise"].as_f64().unwrap();
            assert!(r < 1.2, "{law}, {o}: {r}");
        }
        let params = std::fs::read_to_string(out.join("params.toml")).unwrap();
        assert!(params.contains(&format!("stiffness = \"{law}\"")), "{params}");
        assert!(params.contains(&format!("{own} = ")), "{params}");
        assert_eq!(params.contains("mem_A"), law == "memory", "{params}");
        simulates(&out, &dir.join("sim"));
        if law == "memory" {
            continue;
        }
        let cfg = config(&dir, "", "free = [\"R\", \"mem_A\"]");
        let o = fit_drive(&cfg, &out);
        assert_one_line_error(&o, &["[fit] free 'mem_A'", law]);
    }
}

/// A drive whose friction sits on the load (`--friction-velocity load`: levels of an output
/// bearing, Tc = 8, Ts = 12 N·m) with a constant load torque TL = 0.6 N·m: the params file's
/// `friction_velocity = "load"` carries the setting into the fit, TL is fitted from a start
/// of 0 with the motor's parameters 20–30 % off, and params.toml carries both back to the
/// simulator.
#[test]
fn friction_on_the_load_and_a_load_torque_are_fitted_and_written_back() {
    let load = "friction_velocity = \"load\"\nTc = 8.0\nTs = 12.0\nws = 0.02\nsigma0 = 5e5\nsigma1 = 50.0\n";
    let fit = "free = [\"R\", \"Ke\", \"Jj\", \"Cj\", \"TL\"]\nnoise = { motor = 4.43e-4, load = 1.73e-6 }";
    let (doc, params) =
        fitted_back("fit-compliant-load-friction", &format!("{load}TL = 0.6\n"), load, fit);
    assert_eq!(doc["friction_velocity"], "load");
    let tl = &doc["parameters"]["TL"];
    let (v, se) = (tl["value"].as_f64().unwrap(), tl["std_error"].as_f64().unwrap());
    assert!(tl["determined"].as_bool().unwrap() && (v - 0.6).abs() < 3.0 * se, "TL: {tl}");
    assert!(
        params.contains("friction_velocity = \"load\"") && params.contains("TL = "),
        "{params}"
    );
}

/// A catalogue gear (`stiffness = "catalogue"`, its corners within the record's torques):
/// the fit runs the curve, fit.json and params.toml name the law with its five values and
/// no cubic spring, and `hdw simulate` runs the result.
#[test]
fn a_catalogue_gear_is_fitted_and_written_back() {
    let curve = "stiffness = \"catalogue\"\ncat_K1 = 4e4\ncat_K2 = 8e4\ncat_K3 = 1.2e5\ncat_T1 = 0.15\ncat_T2 = 0.35\n";
    let (doc, written) = fitted_back("fit-compliant-catalogue", curve, curve, MOTOR_FIT);
    assert_eq!(doc["stiffness"], "catalogue");
    let params = &doc["parameters"];
    assert!(params["cat_K2"]["unit"] == "N·m/rad" && params["c"].is_null(), "{params}");
    assert!(written.contains("stiffness = \"catalogue\"") && written.contains("cat_T2 = "));
}

/// Friction across the gear (`friction_velocity = "deflection"` in the params file): the
/// fit runs that drive, fit.json and params.toml say so, and `hdw simulate` runs it.
#[test]
fn friction_across_the_gear_is_carried_through() {
    let law = "friction_velocity = \"deflection\"\nTc = 0.5\nTs = 0.8\nws = 1e-3\nsigma0 = 5e4\nsigma1 = 2.0\n";
    let (doc, params) = fitted_back("fit-compliant-deflection", law, law, MOTOR_FIT);
    assert_eq!(doc["friction_velocity"], "deflection");
    assert!(params.contains("friction_velocity = \"deflection\""), "{params}");
}

/// Friction on both sides: the seed's law on the wave generator and a second law on the
/// load, direction-dependent (Tc_load = 4, Ts_load = 6 N·m forwards, 3 and 4.5 N·m
/// backwards, ωs = 0.02 rad/s, σ0 = 3e5 N·m/rad, σ1 = 40 N·m·s/rad). The load law's four
/// levels are fitted from 20–30 % off with the motor's parameters (the start file setting
/// the negative side's makes them the fit's own), and params.toml carries the law back to
/// the simulator.
#[test]
fn friction_on_both_sides_is_fitted_and_written_back() {
    let law = "ws_load = 0.02\nsigma0_load = 3e5\nsigma1_load = 40.0\n";
    let fit = "free = [\"R\", \"Ke\", \"Jj\", \"Cj\", \"Tc_load\", \"Ts_load\", \"Tc_neg_load\", \"Ts_neg_load\"]\nnoise = { motor = 4.43e-4, load = 1.73e-6 }";
    let (doc, params) = fitted_back(
        "fit-compliant-both-sides",
        &format!("Tc_load = 4.0\nTs_load = 6.0\nTc_neg_load = 3.0\nTs_neg_load = 4.5\n{law}"),
        &format!("Tc_load = 5.0\nTs_load = 4.4\nTc_neg_load = 3.6\nTs_neg_load = 3.4\n{law}"),
        fit,
    );
    assert_eq!(doc["directional_load_friction"], true);
    let levels = [("Tc_load", 4.0), ("Ts_load", 6.0), ("Tc_neg_load", 3.0), ("Ts_neg_load", 4.5)];
    for (name, truth) in levels {
        let p = &doc["parameters"][name];
        let (v, se) = (p["value"].as_f64().unwrap(), p["std_error"].as_f64().unwrap());
        assert!(p["determined"].as_bool().unwrap() && (v - truth).abs() < 3.0 * se, "{name}: {p}");
        assert_eq!(p["unit"], "N·m");
    }
    for name in ["Tc_load = ", "Tc_neg_load = ", "Ts_neg_load = ", "sigma0_load = "] {
        assert!(params.contains(name), "{name} in {params}");
    }
}

/// `axis = "linear"` (a ball screw, a belt): the same fit, its outputs in the load's
/// translation units: Jz in kg, the stiffness in N/m, the load encoder in m, the ratio in
/// rad/m; the motor's own parameters and encoder keep theirs.
#[test]
fn a_linear_axis_carries_its_units_into_every_output() {
    let dir = recorded("fit-compliant-linear", "0.5");
    let cfg = config(&dir, "axis = \"linear\"", "free = [\"R\"]");
    let out = dir.join("out");
    ok(&fit_drive(&cfg, &out));
    let doc = json(&out.join("fit.json"));
    assert_eq!(doc["axis"], "linear");
    let p = &doc["parameters"];
    for (name, unit) in [("Jz", "kg"), ("c", "N/m"), ("Tc", "N"), ("TL", "N"), ("Jj", "kg·m²")] {
        assert_eq!(p[name]["unit"], unit, "{name}");
    }
    let chirp = &doc["experiments"]["chirp"];
    assert_eq!(
        (chirp["load"]["unit"].as_str(), chirp["motor"]["unit"].as_str()),
        (Some("m"), Some("rad"))
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("rad/m") && report.contains("| Jz |"), "{report}");
    let params = std::fs::read_to_string(out.join("params.toml")).unwrap();
    assert!(params.contains("# A linear axis"), "{params}");
    simulates(&out, &dir.join("sim"));
}

#[test]
fn bad_compliant_configurations_get_one_line_errors() {
    let dir = recorded("fit-compliant-bad", "0.1");
    // The configuration with `extra` and `fit`, each experiment line `current = "i"`
    // replaced by `current_line`, run; a failed fit must leave no output folder.
    let run_with = |extra: &str, fit: &str, current_line: &str| {
        let cfg = config(&dir, extra, fit);
        let text = std::fs::read_to_string(&cfg).unwrap().replace("current = \"i\"", current_line);
        std::fs::write(&cfg, text).unwrap();
        let out = dir.join("out");
        let o = fit_drive(&cfg, &out);
        assert!(!out.exists(), "a failed fit leaves no output folder");
        o
    };
    let run = |extra: &str, fit: &str| run_with(extra, fit, "current = \"i\"");
    let cases = [
        ("[params]\nJx = 1.0\n", "", "[params] 'Jx'"),
        ("", "free = [\"R\", \"gain\"]", "[fit] free 'gain'"),
        ("voltage_between = \"spline\"\n", "", "voltage_between"),
        ("", "noise = { torque = 1.0 }", "noise.torque"),
        ("[bounds]\nR = [5.0, 1.0]\n", "", "[bounds] R"),
        ("", "free = [\"R\", \"bw_alpha\"]", "[fit] free 'bw_alpha'"),
        ("[params]\nbw_beta = 1.0\n", "", "[params] 'bw_beta'"),
        ("", "free = [\"R\", \"ms_n\"]", "[fit] free 'ms_n'"),
        ("", "free = [\"R\", \"Tc_neg\"]", "[fit] free 'Tc_neg'"),
        ("friction_velocity = \"wheel\"\n", "", "friction_velocity"),
        ("axis = \"circular\"\n", "", "axis"),
        // The load-side law: named without one, or incomplete, or beside the gear's own
        // law moved to the load.
        ("", "free = [\"R\", \"Tc_load\"]", "[fit] free 'Tc_load'"),
        ("[params]\nTc_load = 2.0\n", "", "sigma0_load"),
        (
            "[params]\nTc_load = 2.0\nsigma0_load = 1e5\nws_load = 0.01\n",
            "free = [\"R\", \"Ts_neg_load\"]",
            "[fit] free 'Ts_neg_load'",
        ),
        (
            "friction_velocity = \"load\"\n[params]\nTc_load = 2.0\nsigma0_load = 1e5\nws_load = 0.01\n",
            "",
            "friction_velocity",
        ),
    ];
    for (extra, fit, expect) in cases {
        // `[params]` and `[bounds]` tables must come after the top-level keys but before
        // [[experiment]]: the helper puts `extra` there.
        let o = run(extra, fit);
        assert_one_line_error(&o, &[expect, "fit.toml"]);
    }
    // A missing column names the file and the column.
    let o = run_with("", "", "current = \"amps\"");
    assert_one_line_error(&o, &["amps", "chirp.csv"]);
    // A params file asking for what the compliant model is not names the file and the key.
    for (line, expect) in [
        ("stiffness = \"catalogue\"\ncat_loss = 1e-4", "cat_loss = 1e-4"),
        ("L = 0.002", "L = 2e-3"),
    ] {
        std::fs::write(dir.join("start.toml"), format!("R = 7.5\n{line}\n")).unwrap();
        let o = run("", "");
        assert_one_line_error(&o, &[expect, "start.toml"]);
    }
    // A load encoder that counts the other way, or a wrong gear ratio, is named before any
    // fitting.
    for (start_file, line, expect) in [
        ("R = 7.5\n", "load_scale = -1.0", "opposite directions"),
        ("R = 7.5\nN = 50\n", "", "moves 0.50"),
    ] {
        std::fs::write(dir.join("start.toml"), start_file).unwrap();
        let o = run_with("", "", &format!("current = \"i\"\n{line}"));
        assert_one_line_error(&o, &[expect, "chirp.csv"]);
    }
}

/// The integration error is measured again at the fitted values. A count the configuration
/// gives is kept; where it is too coarse there (one substep per 1 ms sample of the seed
/// drive's chirp: 70 noise-weighted squares against a budget of 1), the first sentence of
/// the determination says so and names `substeps`. A chosen count meets the budget at the
/// fitted values, says nothing, and the check appears among the stages.
#[test]
fn a_given_substep_count_too_coarse_at_the_fit_is_reported() {
    let dir = recorded("fit-compliant-coarse", "1");
    let sentences = |doc: &serde_json::Value| -> Vec<String> {
        doc["determination"].as_array().unwrap().iter().map(|s| s.to_string()).collect()
    };
    let cfg = config(&dir, "substeps = 1", MOTOR_FIT);
    let out = dir.join("coarse");
    ok(&fit_drive(&cfg, &out));
    let doc = json(&out.join("fit.json"));
    let first = &sentences(&doc)[0];
    assert!(
        first.contains("configuration's 1 Runge–Kutta substeps")
            && first.contains("raise `substeps`"),
        "{first}"
    );
    let cost: f64 =
        first.split("costing ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!(cost > 1.0, "{first}");
    let cfg = config(&dir, "", MOTOR_FIT);
    let out = dir.join("chosen");
    ok(&fit_drive(&cfg, &out));
    let doc = json(&out.join("fit.json"));
    assert!(sentences(&doc).iter().all(|s| !s.contains("integration error costing")));
    let stages: Vec<&str> = doc["stage_seconds"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["stage"].as_str().unwrap())
        .collect();
    assert!(stages.contains(&"integration accuracy at the fitted values"), "{stages:?}");
}
