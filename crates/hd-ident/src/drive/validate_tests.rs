//! The configuration checks: each bad number refused with one line naming the file, the
//! table and the key; the shipped configurations' numbers accepted.

use crate::drive::DriveConfig;
use crate::drive::compliant::CompliantConfig;

/// The shipped EMPS configuration with `extra` put before its first table (top-level keys)
/// or appended (tables), and `replace` pairs applied.
fn rigid(replace: &[(&str, &str)], tables: &str) -> String {
    let mut text = include_str!("../../../../data/emps/fit.toml").to_string();
    for (a, b) in replace {
        assert!(text.contains(a), "{a}");
        text = text.replacen(a, b, 1);
    }
    text + tables
}

/// The error of the rigid configuration `text`, which must be refused.
fn rigid_error(text: &str) -> String {
    let e = DriveConfig::parse(text, "fit.toml").expect_err("refused").to_string();
    assert!(!e.contains('\n'), "one line: {e}");
    assert!(e.starts_with("fit.toml"), "{e}");
    e
}

#[test]
fn shipped_configurations_pass() {
    DriveConfig::parse(&rigid(&[], ""), "fit.toml").unwrap();
    CompliantConfig::parse(include_str!("../../../../data/compliant/fit.toml"), "fit.toml")
        .unwrap();
    CompliantConfig::parse(include_str!("../../../../data/compliant/loop.toml"), "loop.toml")
        .unwrap();
}

#[test]
fn rigid_params_out_of_their_physical_range() {
    for (table, key) in [
        ("[params]\nM = -5.0\n", "[params] M"),
        ("[params]\nM = nan\n", "[params] M"),
        ("[params]\nFc = inf\n", "[params] Fc"),
        ("[params]\nFv = -1.0\n", "[params] Fv"),
        ("[params]\nsigma0 = -1.0\n", "[params] sigma0"),
        ("[params]\nvs = 0.0\n", "[params] vs"),
    ] {
        let e = rigid_error(&rigid(&[], table));
        assert!(e.contains(key) && e.contains("expected a finite value"), "{table}: {e}");
    }
    // The offset may be negative.
    DriveConfig::parse(&rigid(&[], "[params]\noffset = -3.0\n"), "fit.toml").unwrap();
}

#[test]
fn rigid_bounds_ordered_physical_and_holding_the_start() {
    for (table, want) in [
        ("[bounds]\nM = [nan, 2.0]\n", "lower < upper"),
        ("[bounds]\nM = [2.0, 1.0]\n", "lower < upper"),
        ("[bounds]\nM = [inf, inf]\n", "lower < upper"),
        ("[bounds]\nM = [-1.0, 200.0]\n", "lower bound > 0"),
        ("[bounds]\nFc = [-1.0, 200.0]\n", "lower bound ≥ 0"),
        ("[params]\nM = 5.0\n[bounds]\nM = [1.0, 2.0]\n", "excludes the start M = 5"),
    ] {
        let e = rigid_error(&rigid(&[], table));
        assert!(e.contains("[bounds]") && e.contains(want), "{table}: {e}");
    }
    let ok = rigid(&[], "[bounds]\nM = [1.0, inf]\noffset = [-inf, inf]\n");
    DriveConfig::parse(&ok, "fit.toml").unwrap();
}

#[test]
fn rigid_keys_of_another_law_are_named() {
    let text = rigid(
        &[("friction = \"all\"", "friction = \"coulomb-viscous\"")],
        "[params]\nsigma0 = 1e5\n",
    );
    let e = rigid_error(&text);
    assert!(e.contains("[params] sigma0") && e.contains("lugre"), "{e}");
    let text = rigid(
        &[("friction = \"all\"", "friction = \"lugre\"")],
        "[bounds]\nFc_pos = [0.0, 10.0]\n",
    );
    let e = rigid_error(&text);
    assert!(e.contains("[bounds] Fc_pos") && e.contains("directional"), "{e}");
}

#[test]
fn rigid_scales_gains_and_controller_keys() {
    for (replace, key) in [
        (("gain = \"gtau\"", "gain = nan"), "gain"),
        (("gain = \"gtau\"", "gain = 0.0"), "gain"),
        (("gain = \"gtau\"", "gain = -35.0"), "gain"),
        (("gain = \"gtau\"", "gain = inf"), "gain"),
        (("gain = \"gtau\"", "gain = true"), "gain"),
        (("command = \"vir\"", "command = \"vir\"\nposition_scale = 0.0"), "position_scale"),
        (("command = \"vir\"", "command = \"vir\"\ncommand_scale = nan"), "command_scale"),
        (("kp = \"kp\"", "kp = nan"), "[controller] kp"),
        (("kv = \"kv\"", "kv = -1.0"), "[controller] kv"),
        (("speed_filter = [0.5, 0.5]", "speed_filter = [nan]"), "[controller] speed_filter"),
        (("saturation = 10.0", "saturation = nan"), "[controller] saturation"),
        (("delay = \"auto\"", "delay = -1"), "[controller] delay"),
        (("delay = \"auto\"", "delay = 1.5"), "[controller] delay"),
        (("delay = \"auto\"", "delay = 100000"), "[controller] delay"),
        (("delays = [0, 1]", "delays = [0, -1]"), "[controller] delays"),
        (("delays = [0, 1]", "delays = []"), "[controller] delays"),
        (("cutoff_hz = 40.0", "cutoff_hz = -40.0"), "[start] cutoff_hz"),
        (("order = 4", "order = 0"), "[start] order"),
        (("decimate = 10", "decimate = -3"), "[start] decimate"),
        (("fix = [\"gain\"]", "fix = [\"gain\"]\nmax_iterations = -1"), "[fit] max_iterations"),
    ] {
        let e = rigid_error(&rigid(&[replace], ""));
        assert!(e.contains(key) && e.starts_with("fit.toml, "), "{replace:?}: {e}");
        assert!(!e.contains("untagged") && !e.contains("TOML parse error"), "{e}");
    }
}

#[test]
fn duplicate_experiment_names_are_refused() {
    let text = include_str!("../../../../data/emps/fit.toml");
    let exp = &text[text.find("[[experiment]]").unwrap()..text.find("[controller]").unwrap()];
    let doubled = text.replacen(exp, &format!("{exp}{exp}"), 1);
    let e = rigid_error(&doubled);
    assert!(e.contains("'estimation'") && e.contains("used twice"), "{e}");
}

/// The shipped compliant configuration with `replace` applied and `tables` appended.
fn compliant(loop_config: bool, replace: &[(&str, &str)], tables: &str) -> String {
    let mut text = if loop_config {
        include_str!("../../../../data/compliant/loop.toml")
    } else {
        include_str!("../../../../data/compliant/fit.toml")
    }
    .to_string();
    for (a, b) in replace {
        assert!(text.contains(a), "{a}");
        text = text.replacen(a, b, 1);
    }
    text + tables
}

fn compliant_error(text: &str) -> String {
    let e = CompliantConfig::parse(text, "fit.toml").expect_err("refused").to_string();
    assert!(!e.contains('\n') && e.starts_with("fit.toml"), "{e}");
    e
}

#[test]
fn compliant_params_bounds_and_scales() {
    for (table, key) in [
        ("[params]\nJz = inf\n", "[params] Jz"),
        ("[params]\nR = 0.0\n", "[params] R"),
        ("[params]\nR = -1.0\n", "[params] R"),
        ("[params]\nR = nan\n", "[params] R"),
        ("[params]\nsigma0 = -1.0\n", "[params] sigma0"),
        ("[bounds]\nR = [nan, 10.0]\n", "[bounds] R"),
        ("[bounds]\nR = [-1.0, 10.0]\n", "[bounds] R"),
        ("[params]\nR = 7.5\n[bounds]\nR = [1.0, 2.0]\n", "[bounds] R"),
    ] {
        let text = compliant(false, &[("[[experiment]]", &format!("{table}\n[[experiment]]"))], "");
        let e = compliant_error(&text);
        assert!(e.contains(key), "{table}: {e}");
    }
    for (replace, key) in [
        (("current = \"i\"", "current = \"i\"\ncurrent_scale = 0.0"), "current_scale"),
        (("current = \"i\"", "current = \"i\"\nvoltage_scale = nan"), "voltage_scale"),
        (("current = \"i\"", "current = \"i\"\nmotor_scale = inf"), "motor_scale"),
        (("voltage_between", "substeps = 1000000\nvoltage_between"), "substeps"),
        (("voltage_between", "substeps = -2\nvoltage_between"), "substeps"),
    ] {
        let e = compliant_error(&compliant(false, &[replace], ""));
        assert!(e.contains(key), "{replace:?}: {e}");
    }
    // Bouc–Wen's γ may be negative, and its bounds with it.
    let ok = compliant(
        false,
        &[("[[experiment]]", "[bounds]\nbw_gamma = [-1e6, 1e6]\n\n[[experiment]]")],
        "",
    );
    CompliantConfig::parse(&ok, "fit.toml").unwrap();
}

#[test]
fn compliant_loop_controller_keys() {
    for (replace, key) in [
        (("kv = 0.5", "kv = nan"), "[controller] kv"),
        (("kv = 0.5", "kv = -1.0"), "[controller] kv"),
        (("kp = 30.0", "kp = 0.0"), "[controller] kp"),
        (("delay = \"auto\"", "delay = -1"), "[controller] delay"),
        (("delay = \"auto\"", "speed_filter = [nan]"), "[controller] speed_filter"),
        (("command = \"cmd\"", "command = \"cmd\"\ncommand_scale = 0.0"), "command_scale"),
    ] {
        let e = compliant_error(&compliant(true, &[replace], ""));
        assert!(e.contains(key), "{replace:?}: {e}");
        assert!(!e.contains("untagged"), "{e}");
    }
}

#[test]
fn compliant_start_from_the_params_file_inside_bounds() {
    use crate::drive::compliant::params::{P, ix};
    use crate::drive::config::validate_compliant::starts_in_bounds;
    let text =
        compliant(false, &[("[[experiment]]", "[bounds]\nR = [1.0, 2.0]\n\n[[experiment]]")], "");
    let c = CompliantConfig::parse(&text, "fit.toml").unwrap();
    let mut base = [1.0; P];
    base[ix::R] = 7.5;
    let e = starts_in_bounds(&c, "fit.toml", &base).unwrap_err().to_string();
    assert!(e.contains("[bounds] R") && e.contains("the params file"), "{e}");
    base[ix::R] = 1.5;
    starts_in_bounds(&c, "fit.toml", &base).unwrap();
}

#[test]
fn a_delay_longer_than_the_records_is_refused() {
    use crate::drive::config::validate_compliant::with_records;
    let text = compliant(true, &[("delay = \"auto\"", "delay = 100")], "");
    let c = CompliantConfig::parse(&text, "fit.toml").unwrap();
    let e = with_records(&c, "fit.toml", 50).unwrap_err().to_string();
    assert!(e.contains("[controller] delay") && e.contains("50 samples"), "{e}");
    with_records(&c, "fit.toml", 5000).unwrap();
    let rigid_text = rigid(&[("delay = \"auto\"", "delay = 100")], "");
    let r = DriveConfig::parse(&rigid_text, "fit.toml").unwrap();
    let e = crate::drive::config::validate::with_records(&r, "fit.toml", 1e-3, 50).unwrap_err();
    assert!(e.to_string().contains("50 samples"), "{e}");
    let e = crate::drive::config::validate::with_records(
        &DriveConfig::parse(&rigid(&[], ""), "f").unwrap(),
        "f",
        0.1,
        5000,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("[start] cutoff_hz") && e.to_string().contains("Nyquist"),
        "{e}"
    );
}

#[test]
fn a_duplicate_key_is_named() {
    // toml says only "duplicate key" and where; the message quotes the line, so the key is
    // named.
    let e = rigid_error(&rigid(&[], "\n[fit]\nnoise = 1.0\n[fit]\nnoise = 2.0\n"));
    assert!(e.contains("line") && e.contains("[fit]"), "{e}");
    let text =
        "transmission = \"compliant\"\nvoltage_between = \"hold\"\nvoltage_between = \"hold\"\n";
    let e = CompliantConfig::parse(text, "fit.toml").expect_err("refused").to_string();
    assert!(e.contains("duplicate key") && e.contains("voltage_between"), "{e}");
}

/// Magnitudes no drive has: a gain, a scale or a start of 1e300 (each gave NaN parameters
/// and exit 0, or a fit that never moved), a scale of 1e-300; each refused, the number
/// written short. Unit conversions from pico to tera pass.
#[test]
fn magnitudes_beyond_any_drive_are_refused() {
    for (replace, table, key) in [
        (("gain = \"gtau\"", "gain = 1e300"), "", "gain: 1e300"),
        (("gain = \"gtau\"", "gain = 1e-300"), "", "gain: 1e-300"),
        (("kv = \"kv\"", "kv = 1e300"), "", "[controller] kv: 1e300"),
        (("disturbance = ", "command_scale = 1e300\ndisturbance = "), "", "command_scale: 1e300"),
        (
            ("disturbance = ", "position_scale = -1e-300\ndisturbance = "),
            "",
            "position_scale: -1e-300",
        ),
        (("axis", "axis"), "[params]\nM = 1e300\n", "[params] M: 1e300"),
    ] {
        let e = rigid_error(&rigid(&[replace], table));
        assert!(e.contains(key), "{key}: {e}");
        assert!(e.len() < 300, "short: {e}");
    }
    for ok in ["position_scale = 1e-9\n", "command_scale = -1e3\n"] {
        let text = rigid(&[("disturbance = ", &format!("{ok}disturbance = "))], "");
        DriveConfig::parse(&text, "fit.toml").unwrap();
    }
}

/// A given noise level far below the signal (1e-300 gave an infinite BIC and no standard
/// error) is named; a sensor's level passes.
#[test]
fn a_noise_level_below_any_sensor_is_refused() {
    use crate::drive::config::validate::noise_floor;
    let e = noise_floor("fit.toml", "force", 1e-300, 54.1).unwrap_err().to_string();
    assert!(e.contains("[fit] noise.force: 1e-300") && e.contains("RMS"), "{e}");
    noise_floor("fit.toml", "position", 1e-9, 0.1).unwrap();
    noise_floor("fit.toml", "position", 1e-9, 0.0).unwrap();
}
