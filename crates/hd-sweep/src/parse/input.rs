//! Checking the `[input]` section into an [`Input`].

use super::Checker;
use crate::error::StudyError;
use crate::spec::*;
use hd_model::Input;
use hd_model::registry::nearest_of;
use toml::Spanned;

impl Checker<'_> {
    pub(super) fn input(&self, s: &Spanned<InputSpec>) -> Result<Input, StudyError> {
        let at = s.span().start;
        let i = s.get_ref();
        let voltage = i.voltage.unwrap_or(24.0);
        let need = |v: Option<f64>, field: &str| {
            v.ok_or_else(|| {
                self.err(
                    at,
                    &format!("input.{field}"),
                    format!("input kind '{}' needs '{field}'", i.kind.get_ref()),
                )
            })
        };
        let input = match i.kind.get_ref().as_str() {
            "sine" => Input::Sine { amplitude: voltage, freq: i.freq.unwrap_or(50.0) },
            "step" => Input::Step { amplitude: voltage, t0: i.t0.unwrap_or(0.0) },
            "constant" => Input::Constant { amplitude: voltage },
            "chirp" => Input::Chirp {
                amplitude: voltage,
                f0: need(i.f0, "f0")?,
                f1: need(i.f1, "f1")?,
                duration: need(i.duration, "duration")?,
            },
            "stepped_sine" => Input::SteppedSine {
                amplitude: voltage,
                freqs: i
                    .freqs
                    .clone()
                    .ok_or_else(|| self.err(at, "input.freqs", "stepped_sine needs 'freqs'"))?,
                dwell: need(i.dwell, "dwell")?,
            },
            "recorded" => {
                let f = i
                    .file
                    .as_ref()
                    .ok_or_else(|| self.err(at, "input.file", "recorded input needs 'file'"))?;
                let p = self.dir.join(f);
                Input::Recorded((self.loader)(&p).map_err(|e| self.err(at, "input.file", e))?)
            }
            other => {
                let kinds = ["sine", "step", "constant", "chirp", "stepped_sine", "recorded"];
                let hint = nearest_of(other, kinds.into_iter())
                    .map(|s| format!(" (did you mean '{s}'?)"))
                    .unwrap_or_default();
                return Err(self.err(
                    i.kind.span().start,
                    "input.kind",
                    format!(
                        "unknown input kind '{other}'{hint}: expected one of {}",
                        kinds.join(", ")
                    ),
                ));
            }
        };
        input.validate().map_err(|e| self.err(at, "input", e.to_string()))?;
        Ok(input)
    }
}
