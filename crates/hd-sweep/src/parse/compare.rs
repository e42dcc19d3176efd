//! Checking the paper-versus-model statements (`[[compare]]`).

use super::Checker;
use crate::axis::Knob;
use crate::error::StudyError;
use crate::spec::*;
use crate::study::Study;
use hd_model::Variant;
use toml::Spanned;

impl Checker<'_> {
    pub(super) fn compare(
        &self,
        c: &Spanned<CompareSpec>,
        study: &Study,
    ) -> Result<CompareSpec, StudyError> {
        let at = c.span().start;
        let spec = c.get_ref().clone();
        let part = study.parts.iter().find(|p| p.name == spec.part).ok_or_else(|| {
            self.err(at, "compare.part", format!("no part named '{}'", spec.part))
        })?;
        if !part.swept_names().contains(&spec.axis.as_str()) {
            return Err(self.err(
                at,
                "compare.axis",
                format!("part '{}' does not sweep '{}'", spec.part, spec.axis),
            ));
        }
        let sweeps_variant = part.axes.iter().any(|a| matches!(a.knob, Knob::Variant));
        match &spec.variant {
            None if sweeps_variant => {
                return Err(self.err(
                    at,
                    "compare.variant",
                    format!("part '{}' sweeps variants: say which one to compare", spec.part),
                ));
            }
            Some(v) => {
                v.parse::<Variant>().map_err(|e| self.err(at, "compare.variant", e))?;
            }
            None => {}
        }
        if !study.keep_metrics.contains(&spec.metric.as_str()) {
            return Err(self.err(
                at,
                "compare.metric",
                format!("metric '{}' is not kept by this study", spec.metric),
            ));
        }
        if !["increase", "decrease"].contains(&spec.direction.as_str()) {
            return Err(self.err(
                at,
                "compare.direction",
                format!("'{}': expected increase or decrease", spec.direction),
            ));
        }
        if !["up", "down", "flat", "up_or_flat", "down_or_flat"].contains(&spec.expect.as_str()) {
            return Err(self.err(
                at,
                "compare.expect",
                format!("'{}': expected up, down, flat, up_or_flat or down_or_flat", spec.expect),
            ));
        }
        Ok(spec)
    }
}
