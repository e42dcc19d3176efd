//! Which units a record's disturbance column is in, judged by the record itself.
//!
//! A benchmark may log an additive disturbance on the controller's output in force units
//! while its loop adds it to the command (EMPS's validation run: `pulses_N`, which its
//! description calls newtons and its Simulink model adds in volts). The recorded command
//! settles it: the controller's law applied to the recorded position, plus the disturbance
//! read as command units, or as force units (divided by the drive gain), is compared with
//! the recorded command, and the reading that reproduces it best is used. When the recorded
//! command reproduces best with no disturbance at all, it was logged before the
//! disturbance was added, and the record cannot tell the units: the column is then taken in
//! command units, as the configuration says, and the check says so.

use super::controller::{Controller, reproduce};
use super::record::Experiment;

/// One reading of the disturbance column and how well it reproduces the recorded command.
#[derive(Clone, Debug, PartialEq)]
pub struct Reading {
    /// What the reading assumes.
    pub name: &'static str,
    /// Factor from the column to command units [command unit per column unit].
    pub scale: f64,
    /// RMS of recorded − reproduced command [command unit].
    pub rms: f64,
    /// The same as a share of the recorded command's RMS [%].
    pub percent: f64,
}

/// The check of one record's disturbance column.
#[derive(Clone, Debug, PartialEq)]
pub struct DisturbanceCheck {
    /// The record's name.
    pub record: String,
    /// Every reading tried, in the order: command units, force units, absent.
    pub readings: Vec<Reading>,
    /// The factor applied to the column [command unit per column unit].
    pub scale: f64,
    /// One sentence on what was found and used.
    pub sentence: String,
}

/// Judge the units of `e`'s disturbance column with controller `c` (at its delay) and the
/// drive gain [force per command unit]; `None` when the column is all zeros (absent).
pub fn check_units(c: &Controller, e: &Experiment, gain: f64) -> Option<DisturbanceCheck> {
    if e.disturbance.iter().all(|d| *d == 0.0) {
        return None;
    }
    let candidates: [(&'static str, f64); 3] = [
        ("command units, added as logged", 1.0),
        ("force units, divided by the gain", 1.0 / gain),
        ("not in the recorded command", 0.0),
    ];
    let readings: Vec<Reading> = candidates
        .iter()
        .map(|&(name, scale)| {
            let d: Vec<f64> = e.disturbance.iter().map(|v| v * scale).collect();
            let r = reproduce(c, &e.position, &e.reference, &d, &e.command, &[c.delay]);
            Reading { name, scale, rms: r[0].rms, percent: r[0].percent }
        })
        .collect();
    let best =
        readings.iter().min_by(|a, b| a.rms.total_cmp(&b.rms)).expect("three readings").clone();
    let (scale, sentence) = if best.scale == 0.0 {
        (
            1.0,
            format!(
                "{}: the recorded command is reproduced best without the disturbance ({:.3} %), so it was logged before the disturbance was added and cannot tell its units; the column is taken in command units, as configured",
                e.name, best.percent
            ),
        )
    } else {
        let other = readings
            .iter()
            .filter(|r| r.name != best.name)
            .map(|r| format!("{:.3} % {}", r.percent, r.name))
            .collect::<Vec<_>>()
            .join(", ");
        (
            best.scale,
            format!(
                "{}: the disturbance column is in {} (the recorded command is reproduced to {:.3} %, against {other})",
                e.name, best.name, best.percent
            ),
        )
    };
    Some(DisturbanceCheck { record: e.name.clone(), readings, scale, sentence })
}

/// [`check_units`], then the column scaled to command units in `e`.
pub fn settle_units(c: &Controller, e: &mut Experiment, gain: f64) -> Option<DisturbanceCheck> {
    let check = check_units(c, e, gain)?;
    if check.scale != 1.0 {
        e.disturbance.iter_mut().for_each(|d| *d *= check.scale);
    }
    Some(check)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record whose command holds the law plus pulses logged in force units (or in
    /// command units, or not at all): the check finds which, and scales the column.
    #[test]
    fn the_recorded_command_tells_the_units() {
        let c = crate::drive::tests::controller(0);
        let h = c.h;
        let gain = 35.0;
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
        let q: Vec<f64> = t.iter().map(|t| 1e-3 * (3.0 * t).sin()).collect();
        let r: Vec<f64> =
            t.iter().map(|t| 1e-3 * (3.0 * t).sin() + 2e-6 * (40.0 * t).cos()).collect();
        let pulses: Vec<f64> =
            (0..n).map(|k| if (k / 100) % 4 == 1 { 20.0 } else { 0.0 }).collect();
        let record = |scale: f64| {
            let u: Vec<f64> =
                (0..n).map(|k| c.clamp(c.law(r[k], &q, k) + scale * pulses[k])).collect();
            Experiment::new("v", "test", t.clone(), q.clone(), r.clone(), u, pulses.clone())
                .unwrap()
        };
        for (scale, expect) in [(1.0 / gain, 1.0 / gain), (1.0, 1.0), (0.0, 1.0)] {
            let mut e = record(scale);
            let check = settle_units(&c, &mut e, gain).unwrap();
            assert_eq!(check.scale, expect, "{}", check.sentence);
            assert!((e.disturbance[150] - 20.0 * expect).abs() < 1e-12);
        }
        let mut quiet = record(0.0);
        quiet.disturbance = vec![0.0; n];
        assert!(settle_units(&c, &mut quiet, gain).is_none());
    }
}
