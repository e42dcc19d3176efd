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

/// None when the current of `rec` has the scale the drive at `spec.start` gives it from the
/// voltage (R, Ke); otherwise why not, naming the likely factor. Only for voltage tests.
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
    Some(format!(
        "{}: the logged current is {g:.4} times what the start values (R, Ke) drive from the voltage; expected about 1 (within ×{SCALE_LIMIT}): {}. Every value the fit gives is in doubt until it does.",
        rec.source,
        likely(g, "current_scale")
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
    if percent <= CONTROLLER_LIMIT {
        return None;
    }
    let d = c.delay;
    let start = d + c.speed_filter.len();
    let n = rec.len();
    if n <= start {
        return None;
    }
    let rerun: Vec<f64> = (start..n).map(|k| c.clamp(c.law(reference[k - d], q, k - d))).collect();
    let g = gain(&rec.u[start..], &rerun).unwrap_or(f64::NAN);
    let factor = if g.is_finite() && !(0.7..1.4).contains(&g) {
        format!(
            "the recorded command is {g:.4} times the re-run's: kp or kv about {:.3}× what the configuration says, or {}",
            g,
            likely(g, "command_scale")
        )
    } else {
        "check kp, kv, the speed filter, the saturation, the feedback encoder and the delays".into()
    };
    Some(format!(
        "The controller check fails on {}: the configured controller re-run on the recorded encoder and reference leaves {percent:.1} % of the recorded command's RMS (expected a few % at most): {factor}. The fit simulates that controller, so every value it gives is in doubt.",
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
}
