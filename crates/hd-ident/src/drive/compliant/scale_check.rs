//! Whether a record's current and command have the scale the drive gives them, as the
//! encoders are checked against the gear ratio ([`super::ratio_check`]). A current logged in
//! mA read as A is a thousand times what the voltage drives through R: the fit would then
//! bend R, Ke and the friction to absorb it (Tc = 114.8 N·m, truth 0.15) and call the noise
//! re-estimated from the misfit (245 A) the noise. A command whose controller is configured
//! with a wrong gain is not the re-run controller's output.

use super::fit::{CompliantSpec, simulate_on_zeros};
use super::record::VoltageRecord;
use crate::drive::controller::Controller;

/// A gain whose magnitude lies outside [1/`SCALE_LIMIT`, `SCALE_LIMIT`] is named [–]: start
/// values 30 % off move it by 1.3 at most, a unit mistake by 1000.
pub const SCALE_LIMIT: f64 = 5.0;

/// The controller check fails when the best delay leaves more than this share of the
/// recorded command's RMS [%] (a quantised encoder leaves about 0.4 %, a delay one sample
/// off 2.8 % on docs/fit-drive.md's steps).
pub const CONTROLLER_LIMIT: f64 = 10.0;

/// The least-squares gain of `measured` on `model`, both less their means [–], or None
/// when the model is flat.
pub fn gain(measured: &[f64], model: &[f64]) -> Option<f64> {
    let n = measured.len().min(model.len()).max(1) as f64;
    let (mm, ms) = (measured.iter().sum::<f64>() / n, model.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (m, s) in measured.iter().zip(model) {
        sxy += (m - mm) * (s - ms);
        sxx += (s - ms) * (s - ms);
    }
    (sxx > 0.0 && sxy.is_finite()).then(|| sxy / sxx)
}

/// The power of ten nearest `g` [–], and what it likely means for a current [A].
fn likely(g: f64, key: &str) -> String {
    let p = 10f64.powi(g.abs().log10().round() as i32);
    let sign = if g < 0.0 { "−" } else { "" };
    let unit = match (g.abs().log10().round() as i32, key) {
        (3, "current_scale") => " (a current logged in mA)",
        (-3, "current_scale") => " (a current logged in kA)",
        (3, _) => " (mV read as V)",
        _ => "",
    };
    if g < 0.0 && (0.5..2.0).contains(&g.abs()) {
        return format!("it runs the other way: give it a negative {key}");
    }
    format!("likely {key} = {sign}{:e}{unit}", 1.0 / p)
}

/// Largest plausible peak of a drive's test voltage [V]: a record whose voltage peaks above
/// it was likely logged in mV.
pub const PLAUSIBLE_VOLTAGE: f64 = 1000.0;

/// What a current `g` times the one the start drives from the voltage likely means, given
/// the record's peak voltage `peak_u` [V]: a current in other units, or a voltage in other
/// units (which scales the driven current instead). The likelier reading comes first.
fn likely_current(g: f64, peak_u: f64) -> String {
    let power = g.abs().log10().round() as i32;
    if g < 0.0 || power == 0 {
        return likely(g, "current_scale");
    }
    let current = likely(g, "current_scale");
    let voltage = format!(
        "voltage_scale = {:e}{}",
        10f64.powi(power),
        match power {
            -3 => " (a voltage logged in mV)",
            3 => " (a voltage logged in kV)",
            _ => "",
        }
    );
    if power < 0 && peak_u > PLAUSIBLE_VOLTAGE {
        format!(
            "likely {voltage}: the voltage peaks at {peak_u:.4e} V, more than a drive's amplifier gives; or {}",
            current.trim_start_matches("likely ")
        )
    } else {
        format!("{current}, or {voltage}")
    }
}

/// None when the current of `rec` has the scale the drive at `spec.start` gives it from the
/// voltage (R, Ke); otherwise why not, naming the likely factor (of the current or of the
/// voltage). Only for voltage tests.
pub fn check_current(spec: &CompliantSpec, rec: &VoltageRecord) -> Option<String> {
    let meas = rec.current.as_deref()?;
    if rec.closed.is_some() {
        return None;
    }
    let (sim, _, _) = simulate_on_zeros(spec, &spec.drive(spec.start), rec);
    let g = gain(meas, &sim.current)?;
    if (1.0 / SCALE_LIMIT..=SCALE_LIMIT).contains(&g) {
        return None;
    }
    let peak_u = rec.u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    Some(format!(
        "{}: the logged current is {g:.4} times what the start values (R, Ke) drive from the voltage; expected about 1 (within ×{SCALE_LIMIT}): {}. Every value the fit gives is in doubt until it does.",
        rec.source,
        likely_current(g, peak_u)
    ))
}

/// The controller check of a closed-loop record: None when controller `c` (its delay set)
/// reproduces the recorded command within [`CONTROLLER_LIMIT`] (`percent`, the pooled
/// check at that delay); otherwise a sentence with the recorded command's gain on the
/// re-run one and the factor it suggests.
pub fn check_command(
    c: &Controller,
    rec: &VoltageRecord,
    q: &[f64],
    reference: &[f64],
    percent: f64,
) -> Option<String> {
    let recorded = Recorded {
        source: &rec.source,
        command: &rec.u,
        disturbance: None,
        scales: "motor_scale (or load_scale), reference_scale and command_scale",
    };
    command_check(c, &recorded, q, reference, percent, "encoder")
}

/// Smallest |correlation| of the recorded command with the re-run one for which a gain or
/// sign is named: below it the command is not this controller's output at all [–].
pub const FOLLOWS: f64 = 0.9;

/// The correlation of `a` with `b` [–] (NaN when either is flat).
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()).max(1) as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

/// A logged closed loop as the controller check reads it.
pub struct Recorded<'a> {
    /// The record's name (its file).
    pub source: &'a str,
    /// The recorded command [command unit].
    pub command: &'a [f64],
    /// What is added to the controller's output before it is logged, if anything.
    pub disturbance: Option<&'a [f64]>,
    /// The configuration keys that scale the fed-back position, the reference and the
    /// command, as the sentence names them.
    pub scales: &'a str,
}

/// [`check_command`] for any logged loop: `q` the fed-back position (`what` names it in the
/// sentence), `reference` the reference, `percent` the pooled check at the controller's delay.
pub fn command_check(
    c: &Controller,
    rec: &Recorded<'_>,
    q: &[f64],
    reference: &[f64],
    percent: f64,
    what: &str,
) -> Option<String> {
    if percent <= CONTROLLER_LIMIT {
        return None;
    }
    let d = c.delay;
    let start = d + c.speed_filter.len();
    let n = rec.command.len().min(q.len()).min(reference.len());
    if n <= start {
        return None;
    }
    let added = |k: usize| rec.disturbance.map_or(0.0, |w| w[k]);
    let rerun: Vec<f64> =
        (start..n).map(|k| c.clamp(c.law(reference[k - d], q, k - d) + added(k - d))).collect();
    let g = gain(&rec.command[start..n], &rerun).unwrap_or(f64::NAN);
    let rho = correlation(&rec.command[start..n], &rerun);
    let factor = if rho.is_nan() || rho.abs() < FOLLOWS {
        format!(
            "the recorded command hardly follows the re-run one (correlation {rho:.2}): check that the command column is the controller's output, then kp, kv, the speed filter, the delays and the {what}'s sign and scale"
        )
    } else if g.is_finite() && g < 0.0 {
        format!(
            "the recorded command is {g:.4} times the re-run's, of the other sign: the command counts the other way against the position and the reference; check the signs of {}",
            rec.scales
        )
    } else if g.is_finite() && !(0.7..1.4).contains(&g) {
        format!(
            "the recorded command is {g:.4} times the re-run's: kp or kv about {:.3}× what the configuration says, or {}; a {what} with the wrong sign or scale does this too",
            g,
            likely(g, "command_scale")
        )
    } else {
        format!(
            "check kp, kv, the speed filter, the saturation, the delays and the {what}'s sign and scale"
        )
    };
    Some(format!(
        "The controller check fails on {}: the configured controller re-run on the recorded {what} and reference leaves {percent:.1} % of the recorded command's RMS (expected a few % at most): {factor}. The fit simulates that controller, so every value it gives is in doubt.",
        rec.source
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A current 1000 times the model's names mA; one near it passes; a reversed one names
    /// the sign.
    #[test]
    fn gains_are_named() {
        let model: Vec<f64> = (0..100).map(|k| (k as f64 * 0.1).sin()).collect();
        let ma: Vec<f64> = model.iter().map(|v| 1000.0 * v + 3.0).collect();
        assert!((gain(&ma, &model).unwrap() - 1000.0).abs() < 1e-9);
        assert!(
            likely(1000.0, "current_scale")
                .contains("current_scale = 1e-3 (a current logged in mA)")
        );
        assert!(likely(-1.0, "current_scale").contains("negative current_scale"));
        assert!(likely(0.1, "command_scale").contains("command_scale = 1e1"));
    }

    /// A current a thousandth of the driven one names the voltage first when the voltage
    /// peaks above what an amplifier gives (a voltage in mV), the current first otherwise.
    #[test]
    fn a_voltage_in_millivolts_is_named() {
        let mv = likely_current(1e-3, 12_000.0);
        assert!(mv.starts_with("likely voltage_scale = 1e-3 (a voltage logged in mV)"), "{mv}");
        assert!(mv.contains("current_scale = 1e3"), "{mv}");
        let ka = likely_current(1e-3, 12.0);
        assert!(ka.starts_with("likely current_scale = 1e3"), "{ka}");
        assert!(ka.contains("or voltage_scale = 1e-3"), "{ka}");
        let ma = likely_current(1000.0, 12.0);
        assert!(ma.starts_with("likely current_scale = 1e-3 (a current logged in mA)"), "{ma}");
    }
}
