//! Every stiffness law fitted to the same record and ranked by the Bayesian information
//! criterion `BIC = n·ln(RSS/n) + p·ln n` (lower is better), with Akaike's
//! `AIC = n·ln(RSS/n) + 2p` beside it. p charges every parameter the fit chose: the
//! spring's three, the offset, and for Maxwell-slip two per element that kept a positive
//! stiffness (its stiffness and its refined yield deflection), so extra elements must pay
//! for themselves: with n = 50 000 samples each costs ln n ≈ 10.8, i.e. it must lower the
//! RSS by a share of about 2·10.8/n. A law whose fit fails is recorded with its error and
//! ranked last; the others go on.

use super::{Law, LawFit, LawOptions, fit_law};
use crate::data::HysteresisData;
use crate::error::chain;
use serde::Serialize;

/// One law's line of comparison.json.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ComparisonEntry {
    /// The law's name.
    pub law: String,
    /// RMS residual [N·m] (null when the fit failed).
    pub rms: Option<f64>,
    /// Akaike information criterion [–].
    pub aic: Option<f64>,
    /// Bayesian information criterion [–].
    pub bic: Option<f64>,
    /// BIC minus the best law's BIC [–].
    pub delta_bic: Option<f64>,
    /// Parameters charged by the criteria.
    pub parameters: usize,
    /// Why the fit failed, when it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The comparison: entries best first, and each successful fit.
pub struct Comparison {
    /// Entries ordered by BIC, failed fits last.
    pub entries: Vec<ComparisonEntry>,
    /// The successful fits, in the same order.
    pub fits: Vec<LawFit>,
    /// Samples in the record.
    pub samples: usize,
}

pub use crate::criteria::criteria;

/// Fit every law to `data` and rank them.
pub fn compare_laws(data: &HysteresisData, opts: &LawOptions) -> Comparison {
    let n = data.len();
    let mut done: Vec<(ComparisonEntry, Option<LawFit>)> = Law::ALL
        .into_iter()
        .map(|law| {
            let o = if law == Law::Memory {
                opts.clone()
            } else {
                LawOptions { fixed: Default::default(), ..opts.clone() }
            };
            match fit_law(data, law, &o) {
                Ok(fit) => {
                    let (aic, bic) = criteria(fit.rss(), n, fit.charged);
                    let entry = ComparisonEntry {
                        law: law.name().into(),
                        rms: Some(fit.report.rms),
                        aic: Some(aic),
                        bic: Some(bic),
                        delta_bic: None,
                        parameters: fit.charged,
                        error: None,
                    };
                    (entry, Some(fit))
                }
                Err(e) => (
                    ComparisonEntry {
                        law: law.name().into(),
                        rms: None,
                        aic: None,
                        bic: None,
                        delta_bic: None,
                        parameters: 0,
                        error: Some(chain(&e)),
                    },
                    None,
                ),
            }
        })
        .collect();
    done.sort_by(|a, b| {
        a.0.bic.unwrap_or(f64::INFINITY).total_cmp(&b.0.bic.unwrap_or(f64::INFINITY))
    });
    let best = done.first().and_then(|d| d.0.bic);
    let mut entries = Vec::new();
    let mut fits = Vec::new();
    for (mut e, f) in done {
        e.delta_bic = e.bic.zip(best).map(|(b, best)| b - best);
        entries.push(e);
        fits.extend(f);
    }
    Comparison { entries, fits, samples: n }
}

impl Comparison {
    /// comparison.json: the entries, best first.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(&self.entries).expect("entries always serialise")
    }

    /// comparison.md: a table and a sentence on the verdict.
    pub fn to_markdown(&self, source: &str) -> String {
        let mut s = format!(
            "# Stiffness laws compared\n\nData: `{source}`, {} samples. Ranked by BIC = n·ln(RSS/n) + p·ln n (lower is better); p counts every parameter the fit chose.\n\n| rank | law | RMS [N·m] | parameters | AIC | BIC | ΔBIC |\n|---|---|---|---|---|---|---|\n",
            self.samples
        );
        let f =
            |v: Option<f64>, prec: usize| v.map_or("–".to_string(), |v| format!("{v:.prec$}"));
        for (i, e) in self.entries.iter().enumerate() {
            let rms = e.rms.map_or("–".to_string(), |v| format!("{v:.4e}"));
            s += &format!(
                "| {} | `{}` | {rms} | {} | {} | {} | {} |\n",
                i + 1,
                e.law,
                e.parameters,
                f(e.aic, 1),
                f(e.bic, 1),
                f(e.delta_bic, 1)
            );
        }
        let ok: Vec<&ComparisonEntry> = self.entries.iter().filter(|e| e.bic.is_some()).collect();
        if let [best, second, ..] = ok.as_slice() {
            let ratio = second.rms.zip(best.rms).map_or(f64::NAN, |(a, b)| a / b);
            s += &format!(
                "\nThe data support `{}`: its BIC is {:.1} below that of `{}`, whose RMS residual is {ratio:.2}× larger. A ΔBIC above 10 is conventionally very strong evidence.\n",
                best.law,
                second.delta_bic.unwrap_or(f64::NAN),
                second.law
            );
        }
        for e in self.entries.iter().filter(|e| e.error.is_some()) {
            s += &format!(
                "\n`{}` could not be fitted: {}\n",
                e.law,
                e.error.as_deref().unwrap_or("")
            );
        }
        s
    }
}
