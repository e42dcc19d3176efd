//! Checking random and sensitivity designs (`[sample]`).

use super::Checker;
use crate::axis::Knob;
use crate::design::{Bound, Sample, SampleMethod};
use crate::error::StudyError;
use crate::sensitivity::{morris_design, saltelli_design};
use crate::spec::*;
use hd_model::Input;
use hd_model::registry::nearest_of;
use toml::Spanned;

impl Checker<'_> {
    pub(super) fn sample(
        &self,
        s: &Spanned<SampleSpec>,
        input: &Input,
    ) -> Result<Sample, StudyError> {
        let at = s.span().start;
        let sp = s.get_ref();
        let methods = ["lhs", "random", "sobol", "morris"];
        let method = match sp.method.get_ref().as_str() {
            "lhs" => SampleMethod::Lhs,
            "random" => SampleMethod::Random,
            "sobol" => SampleMethod::Sobol,
            "morris" => SampleMethod::Morris,
            other => {
                let hint = nearest_of(other, methods.into_iter())
                    .map(|m| format!(" (did you mean '{m}'?)"))
                    .unwrap_or_default();
                return Err(self.err(
                    sp.method.span().start,
                    "sample.method",
                    format!(
                        "unknown sampling method '{other}'{hint}: expected {}",
                        methods.join(", ")
                    ),
                ));
            }
        };
        let n = self.sample_count(sp, method, at)?;
        if sp.param.is_empty() {
            return Err(self.err(at, "sample.param", "expected at least one [[sample.param]]"));
        }
        let bounds =
            sp.param.iter().map(|b| self.bound(b, input)).collect::<Result<Vec<_>, _>>()?;
        let seed = sp.seed.as_ref().map(|s| *s.get_ref());
        let design = match method {
            SampleMethod::Lhs | SampleMethod::Random => None,
            SampleMethod::Sobol => Some(saltelli_design(bounds.len(), n, seed)),
            SampleMethod::Morris => {
                let levels = sp.levels.as_ref().map_or(4, |l| *l.get_ref());
                Some(morris_design(bounds.len(), n, levels, seed.unwrap_or(0)))
            }
        };
        let design = design
            .transpose()
            .map_err(|e| self.err(at, &format!("sample ({})", method.name()), e.to_string()))?;
        Ok(Sample { method, n, seed, bounds, design })
    }

    /// The count of a sample: `n` (lhs, random, sobol) or `trajectories` (morris); fields
    /// that do not apply to the method are errors, so a typo cannot pass silently.
    fn sample_count(
        &self,
        sp: &SampleSpec,
        method: SampleMethod,
        at: usize,
    ) -> Result<usize, StudyError> {
        let m = method.name();
        let (wanted, stray) = match method {
            SampleMethod::Morris => (&sp.trajectories, [("n", &sp.n), ("levels", &None)]),
            _ => (&sp.n, [("trajectories", &sp.trajectories), ("levels", &sp.levels)]),
        };
        if let Some((field, v)) = stray.iter().find_map(|(f, v)| v.as_ref().map(|v| (f, v))) {
            let instead = match method {
                SampleMethod::Morris => "trajectories",
                _ => "n",
            };
            return Err(self.err(
                v.span().start,
                &format!("sample.{field}"),
                format!("'{field}' does not apply to method '{m}' (it takes '{instead}')"),
            ));
        }
        let field = if method == SampleMethod::Morris { "trajectories" } else { "n" };
        let Some(count) = wanted else {
            return Err(self.err(
                at,
                &format!("sample.{field}"),
                format!("method '{m}' needs '{field}'"),
            ));
        };
        if *count.get_ref() == 0 {
            return Err(self.err(
                count.span().start,
                &format!("sample.{field}"),
                "expected at least 1",
            ));
        }
        Ok(*count.get_ref())
    }

    /// One `[[sample.param]]`: a known, sampleable name and bounds inside its valid range.
    fn bound(&self, b: &Spanned<BoundSpec>, input: &Input) -> Result<Bound, StudyError> {
        let bp = b.get_ref();
        let key = format!("sample.param '{}'", bp.name.get_ref());
        let knob = self.knob(&bp.name, "sample.param.name", input)?;
        if matches!(knob, Knob::Variant | Knob::Stiffness) {
            return Err(self.err(
                bp.name.span().start,
                &key,
                format!("{} cannot be sampled; use an axis", knob.name()),
            ));
        }
        let (lo, hi) = (*bp.lo.get_ref(), *bp.hi.get_ref());
        knob.check(lo).map_err(|e| self.err(bp.lo.span().start, &key, format!("lo: {e}")))?;
        knob.check(hi).map_err(|e| self.err(bp.hi.span().start, &key, format!("hi: {e}")))?;
        if lo >= hi {
            return Err(self.err(
                bp.lo.span().start,
                &key,
                format!("expected lo < hi, got lo = {lo}, hi = {hi}"),
            ));
        }
        if bp.log && lo <= 0.0 {
            return Err(self.err(bp.lo.span().start, &key, "log sampling needs lo > 0"));
        }
        Ok(Bound { knob, lo, hi, log: bp.log })
    }
}
