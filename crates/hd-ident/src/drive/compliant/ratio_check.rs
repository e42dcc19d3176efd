//! Whether a record's two encoders agree with the gear ratio. The gear's deflection is a
//! small share of the load's motion (a count or two of a fine load encoder), so the load
//! encoder must follow the motor encoder divided by N. A load encoder that moves the other
//! way, or by another factor, means a sign or scale missing from the configuration (counts
//! read as radians, a motor encoder on the motor's other side) or a wrong N: the fit would
//! bend every parameter to absorb it, so it is refused before fitting, named.

use super::record::VoltageRecord;

/// Largest relative departure of the load-to-motor slope from 1/N that is accepted [–].
pub const RATIO_TOLERANCE: f64 = 0.1;

/// The least-squares slope of the load encoder's motion against the motor encoder's motion
/// divided by `n` [–] (1 for a stiff gear), or None when the motor does not move.
pub fn load_slope(rec: &VoltageRecord, n: f64) -> Option<f64> {
    let (m0, l0) = (rec.theta_m[0], rec.theta_l[0]);
    let mut sxy = 0.0;
    let mut sxx = 0.0;
    for (m, l) in rec.theta_m.iter().zip(&rec.theta_l) {
        let x = (m - m0) / n;
        sxy += x * (l - l0);
        sxx += x * x;
    }
    (sxx > 0.0).then(|| sxy / sxx)
}

/// Fewest samples a record of the compliant drive may have: a few ticks of a voltage test
/// say nothing of the drive's dynamics, and their encoders move by a count or two, too
/// little to check the ratio with (the same floor as `hdw synth drive`'s).
pub const MIN_SAMPLES: usize = 50;

/// None when `rec` has at least [`MIN_SAMPLES`] samples; otherwise why it is refused.
pub fn check_length(rec: &VoltageRecord) -> Option<String> {
    let n = rec.len();
    (n < MIN_SAMPLES).then(|| {
        format!(
            "{}: {n} samples; expected a record of at least {MIN_SAMPLES} samples (a voltage test long enough to show the drive's dynamics: usually thousands)",
            rec.source
        )
    })
}

/// None when the encoders of `rec` agree with ratio `n`; otherwise why not, in one sentence.
pub fn check_ratio(rec: &VoltageRecord, n: f64) -> Option<String> {
    let slope = load_slope(rec, n)?;
    if (slope - 1.0).abs() <= RATIO_TOLERANCE {
        return None;
    }
    let hint = if slope < 0.0 {
        "the encoders count in opposite directions: give one of them a negative scale (load_scale or motor_scale)"
    } else {
        "check the gear ratio N (params file) and the encoders' scales to rad (motor_scale, load_scale)"
    };
    Some(format!(
        "{}: the load encoder moves {slope:.4} times the motor encoder divided by N = {n}; expected 1 within {:.0} % (the gear's deflection is small): {hint}",
        rec.source,
        100.0 * RATIO_TOLERANCE
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(scale: f64, n: f64) -> VoltageRecord {
        let t: Vec<f64> = (0..200).map(|k| k as f64 * 1e-3).collect();
        let m: Vec<f64> = t.iter().map(|t| (40.0 * t).sin() * 3.0).collect();
        // A small deflection on top of the geared motion.
        let l: Vec<f64> = m.iter().map(|m| scale * (m / n + 1e-6 * m.cos())).collect();
        VoltageRecord::new("r", "r.csv", t.clone(), vec![0.0; t.len()], m, l, None).unwrap()
    }

    /// A record geared by N passes; a reversed load encoder, one in counts, and a wrong N
    /// are each refused with their hint.
    #[test]
    fn slopes_of_good_and_bad_records() {
        assert!(check_ratio(&rec(1.0, 100.0), 100.0).is_none());
        let reversed = check_ratio(&rec(-1.0, 100.0), 100.0).unwrap();
        assert!(reversed.contains("opposite directions"), "{reversed}");
        let counts = check_ratio(&rec(166_886.0, 100.0), 100.0).unwrap();
        assert!(counts.contains("scales"), "{counts}");
        let wrong_n = check_ratio(&rec(1.0, 50.0), 100.0).unwrap();
        assert!(wrong_n.contains("2.0000 times"), "{wrong_n}");
    }
}
