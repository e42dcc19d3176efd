//! How a record was sampled, as the compliant configuration says it: how the voltage runs
//! between samples (`voltage_between`, default `hold`) and which instant the logged current
//! refers to (`current_sampled`, default `after`). docs/fit-drive.md, "The compliant drive".

use super::config::CompliantConfig;
use super::record::{Between, CurrentSampled};
use crate::drive::error::DriveError;

/// `voltage_between` when the configuration does not say: a digital amplifier (and
/// `hdw synth drive`) holds each sample until the next. A held record fitted as `linear`
/// misses by 15.6, 3.7 and 1.29 times the noise on motor, load and current (issue 50).
pub const DEFAULT_BETWEEN: Between = Between::Hold;

/// The configuration's `current_sampled`: `after` (default) or `before`.
pub fn current_sampled(c: &CompliantConfig, file: &str) -> Result<CurrentSampled, DriveError> {
    match c.current_sampled.as_deref() {
        None => Ok(CurrentSampled::default()),
        Some(s) => CurrentSampled::parse(s).ok_or_else(|| {
            DriveError::config(
                format!("{file}, current_sampled"),
                format!(
                    "'{s}'; expected \"after\" (the current read just after the new voltage is applied) or \"before\" (just before it)"
                ),
            )
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(extra: &str) -> Result<CompliantConfig, DriveError> {
        let text = format!(
            "transmission = \"compliant\"\n{extra}\n[[experiment]]\nname = \"a\"\nfile = \"a.csv\"\n\
             time = \"t\"\nvoltage = \"u\"\nmotor = \"m\"\nload = \"l\"\n"
        );
        CompliantConfig::parse(&text, "fit.toml")
    }

    /// The defaults are what a digital amplifier's log holds: the voltage held, the current
    /// read after the new voltage; `before` is accepted and a wrong word names the key.
    #[test]
    fn defaults_and_choices() {
        let c = parse("").unwrap();
        assert_eq!(c.between("fit.toml").unwrap(), Between::Hold);
        assert_eq!(current_sampled(&c, "fit.toml").unwrap(), CurrentSampled::After);
        let c = parse("current_sampled = \"before\"").unwrap();
        assert_eq!(current_sampled(&c, "fit.toml").unwrap(), CurrentSampled::Before);
        let e = parse("current_sampled = \"middle\"").unwrap_err().to_string();
        assert!(e.contains("current_sampled") && e.contains("before"), "{e}");
    }
}
