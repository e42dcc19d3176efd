//! The `[score]` table of a fit configuration: which samples of each record the scores
//! count, and which score heads the report. A benchmark's own validation script often
//! leaves out the first samples of each record, where its filters have not settled (EMPS:
//! `n_border = 50`, MATLAB's 1-based index of the first sample scored, so 49 samples are
//! dropped). Scoring the same samples makes a fit's figures comparable with the published
//! ones; the all-samples score is always given beside the rule's.
//!
//! ```toml
//! [score]
//! rule = "emps"            # or "all" (default); or skip_first / skip_last by hand
//! metric = "rel_error"     # rel_error (default), rmse or fit_percent
//! ```

use super::error::DriveError;
use super::score::{Score, score};
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Samples the EMPS benchmark's scripts leave out at the start of a record [samples].
pub const EMPS_SKIP_FIRST: usize = 49;

/// `[score]` as written in the configuration.
#[derive(Clone, Debug, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct ScoreConfig {
    /// `"all"` (every sample, default) or `"emps"` (the first 49 samples dropped).
    pub rule: Option<String>,
    /// Samples dropped at the start of each record [samples]; not with `rule = "emps"`.
    pub skip_first: Option<usize>,
    /// Samples dropped at the end of each record [samples]; not with `rule = "emps"`.
    pub skip_last: Option<usize>,
    /// The score that heads the report: `rel_error` (default), `rmse` or `fit_percent`.
    pub metric: Option<String>,
}

/// The rule, resolved: a name and the samples it drops at each end.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ScoreRule {
    /// `all`, `emps` or `custom`.
    pub name: String,
    /// Samples dropped at the start [samples].
    pub skip_first: usize,
    /// Samples dropped at the end [samples].
    pub skip_last: usize,
    /// The headline score: `rel_error`, `rmse` or `fit_percent`.
    pub metric: String,
}

/// One output's score by the rule, with the all-samples score beside it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RuledScore {
    /// Scores over the samples the rule keeps (NaN when it keeps none).
    pub rule: Score,
    /// Scores over every sample.
    pub all: Score,
    /// Samples the rule kept [samples].
    pub samples: usize,
}

const METRICS: [&str; 3] = ["rel_error", "rmse", "fit_percent"];

impl ScoreConfig {
    /// Check the table; errors name `file` and the key.
    pub fn check(&self, file: &str) -> Result<(), DriveError> {
        let at = |k: &str| format!("{file}, [score] {k}");
        match self.rule.as_deref() {
            None | Some("all") => {}
            Some("emps") => {
                if self.skip_first.is_some() || self.skip_last.is_some() {
                    return Err(DriveError::config(
                        at("rule"),
                        "\"emps\" fixes the samples scored (the first 49 dropped); remove skip_first and skip_last, or the rule",
                    ));
                }
            }
            Some(r) => {
                return Err(DriveError::config(
                    at("rule"),
                    format!("'{r}'; expected \"all\" or \"emps\" (or skip_first / skip_last)"),
                ));
            }
        }
        if let Some(m) = &self.metric
            && !METRICS.contains(&m.as_str())
        {
            return Err(DriveError::config(
                at("metric"),
                format!("'{m}'; expected \"rel_error\", \"rmse\" or \"fit_percent\""),
            ));
        }
        Ok(())
    }

    /// The rule this table sets (call [`ScoreConfig::check`] first).
    pub fn rule(&self) -> ScoreRule {
        let metric = self.metric.clone().unwrap_or_else(|| "rel_error".into());
        let (name, skip_first, skip_last) = match self.rule.as_deref() {
            Some("emps") => ("emps", EMPS_SKIP_FIRST, 0),
            _ => {
                let (a, b) = (self.skip_first.unwrap_or(0), self.skip_last.unwrap_or(0));
                (if a + b == 0 { "all" } else { "custom" }, a, b)
            }
        };
        ScoreRule { name: name.into(), skip_first, skip_last, metric }
    }
}

impl Default for ScoreRule {
    fn default() -> Self {
        ScoreConfig::default().rule()
    }
}

impl ScoreRule {
    /// The samples scored of a record of `n` samples (empty if the rule drops them all).
    pub fn range(&self, n: usize) -> Range<usize> {
        let end = n.saturating_sub(self.skip_last);
        self.skip_first.min(end)..end
    }

    /// Whether the rule scores every sample.
    pub fn is_all(&self) -> bool {
        self.skip_first == 0 && self.skip_last == 0
    }

    /// The rule in words, e.g. "emps: the first 49 samples dropped (the benchmark's
    /// n_border = 50)".
    pub fn describe(&self) -> String {
        let mut parts = Vec::new();
        if self.skip_first > 0 {
            parts.push(format!("the first {} samples dropped", self.skip_first));
        }
        if self.skip_last > 0 {
            parts.push(format!("the last {} samples dropped", self.skip_last));
        }
        let what = if parts.is_empty() { "every sample".to_string() } else { parts.join(", ") };
        match self.name.as_str() {
            "emps" => format!("emps: {what} (the benchmark's n_border = 50)"),
            n => format!("{n}: {what}"),
        }
    }

    /// Score `sim` against `meas` over the rule's samples and over all of them.
    pub fn score(&self, meas: &[f64], sim: &[f64]) -> RuledScore {
        let r = self.range(meas.len().min(sim.len()));
        let rule = if r.is_empty() {
            Score { rel_error: f64::NAN, rmse: f64::NAN, fit_percent: f64::NAN }
        } else {
            score(&meas[r.clone()], &sim[r.clone()])
        };
        RuledScore { rule, all: score(meas, sim), samples: r.len() }
    }

    /// The headline metric's value of `s`.
    pub fn headline(&self, s: &Score) -> f64 {
        match self.metric.as_str() {
            "rmse" => s.rmse,
            "fit_percent" => s.fit_percent,
            _ => s.rel_error,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ScoreRule, String> {
        #[derive(Deserialize)]
        struct Doc {
            #[serde(default)]
            score: ScoreConfig,
        }
        let d: Doc = toml::from_str(text).map_err(|e| e.to_string())?;
        d.score.check("fit.toml").map_err(|e| e.to_string())?;
        Ok(d.score.rule())
    }

    #[test]
    fn rules_parse_and_refuse() {
        assert!(parse("").unwrap().is_all());
        let e = parse("[score]\nrule = \"emps\"").unwrap();
        assert_eq!((e.skip_first, e.skip_last, e.metric.as_str()), (49, 0, "rel_error"));
        assert_eq!(e.range(24_841), 49..24_841);
        let c = parse("[score]\nskip_first = 10\nskip_last = 5\nmetric = \"rmse\"").unwrap();
        assert_eq!((c.name.as_str(), c.range(100)), ("custom", 10..95));
        assert_eq!(c.range(12), 7..7);
        for bad in [
            "[score]\nrule = \"nfl\"",
            "[score]\nrule = \"emps\"\nskip_first = 3",
            "[score]\nmetric = \"r2\"",
            "[score]\nskip = 3",
        ] {
            let e = parse(bad).unwrap_err();
            assert!(e.contains("score") || e.contains("skip"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_rule_scores_only_its_samples() {
        // An error of 1 on the first two samples only: the rule that drops them scores 0.
        let meas = [3.0, 4.0, 1.0, -1.0, 1.0, -1.0];
        let sim = [2.0, 5.0, 1.0, -1.0, 1.0, -1.0];
        let r =
            ScoreRule { name: "custom".into(), skip_first: 2, skip_last: 0, metric: "rmse".into() };
        let s = r.score(&meas, &sim);
        assert_eq!((s.samples, s.rule.rmse, s.rule.rel_error), (4, 0.0, 0.0));
        // All samples: ‖e‖ = √2 over ‖y‖ = √29.
        assert!((s.all.rel_error - 100.0 * (2.0f64 / 29.0).sqrt()).abs() < 1e-12);
        assert!((s.all.rmse - (2.0f64 / 6.0).sqrt()).abs() < 1e-12);
        assert_eq!(r.headline(&s.all), s.all.rmse);
        let none = ScoreRule { skip_first: 6, ..r }.score(&meas, &sim);
        assert!(none.rule.rel_error.is_nan() && none.samples == 0);
    }
}
