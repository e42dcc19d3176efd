//! Deciding whether the data determine a parameter, and saying why not in a sentence.

/// Relative standard error above which a parameter counts as not determined (25 %: the
/// 95 % interval then spans about ±50 % of the value).
pub const REL_SE_LIMIT: f64 = 0.25;

/// What a parameter does in the model and what data would reveal it; supplied by each
/// fit problem and used in the notes.
#[derive(Clone, Debug, PartialEq)]
pub struct Explanation {
    /// The model term, e.g. `a·θ³`.
    pub effect: String,
    /// What data would determine it, e.g. `a wider deflection range than … would reveal it`.
    pub remedy: String,
}

/// Everything the judgement of one free parameter needs.
pub(crate) struct Judgement<'a> {
    pub name: &'a str,
    pub unit: &'a str,
    pub value: f64,
    pub std_error: Option<f64>,
    pub singular: bool,
    /// Bound the linear solve held it at, if any.
    pub at_bound: Option<f64>,
    /// Searched range when the search ended at its edge.
    pub at_edge: Option<(f64, f64)>,
    /// RMS of the parameter's term in the output (linear parameters), or RMS change of
    /// the output for a 1 % change (the nonlinear parameter).
    pub contribution: f64,
    pub nonlinear: bool,
    /// Residual standard deviation and the output's unit.
    pub noise: f64,
    pub output_unit: &'a str,
    /// The most correlated other parameter and the correlation.
    pub strongest: Option<(&'a str, f64)>,
    pub explanation: &'a Explanation,
}

/// The report entry of a free (fitted) parameter: the verdict and note of [`judge`], its
/// standard error and the 95 % interval `value ± t95·se` (`t95`: Student's t quantile for
/// the fit's degrees of freedom).
pub(crate) fn free_estimate(j: &Judgement, unit: &'static str, t95: f64) -> super::Estimate {
    let (determined, note) = judge(j);
    super::Estimate {
        value: j.value,
        unit,
        std_error: j.std_error,
        ci95: j.std_error.map(|se| [j.value - t95 * se, j.value + t95 * se]),
        determined,
        fixed: false,
        note,
    }
}

/// Whether the parameter is determined, and the note saying why not.
pub(crate) fn judge(j: &Judgement) -> (bool, Option<String>) {
    let ex = j.explanation;
    let corr = j
        .strongest
        .map(|(n, r)| format!(" (closest: {n}, correlation {r:+.3})"))
        .unwrap_or_default();
    if j.singular {
        return (
            false,
            Some(format!(
                "near-singular information: over this data {} is almost a combination of the other terms{corr}, so the data cannot fix its value; {}",
                ex.effect, ex.remedy
            )),
        );
    }
    if let Some((lo, hi)) = j.at_edge {
        return (
            false,
            Some(format!(
                "the best {} lies at the edge of the searched range [{lo:.3e}, {hi:.3e}] {}, so the data bound it from one side only; {}",
                j.name, j.unit, ex.remedy
            )),
        );
    }
    if let Some(b) = j.at_bound {
        return (
            false,
            Some(format!(
                "held at its bound {b} {} because the unconstrained optimum falls outside the valid range; {}",
                j.unit, ex.remedy
            )),
        );
    }
    let rse = j.std_error.map_or(f64::INFINITY, |se| se / j.value.abs());
    if rse.is_nan() || rse > REL_SE_LIMIT {
        let rse_text = if rse.is_finite() {
            format!("relative standard error {:.3} %", 100.0 * rse)
        } else {
            "the value is zero within its standard error".to_string()
        };
        let limit = 100.0 * REL_SE_LIMIT;
        let why = if j.contribution < j.noise {
            if j.nonlinear {
                format!(
                    "a 1 % change of {} moves the prediction by only {:.2e} {} RMS, below the noise of {:.2e} {} RMS",
                    j.name, j.contribution, j.output_unit, j.noise, j.output_unit
                )
            } else {
                format!(
                    "{} amounts to only {:.2e} {} RMS over the data, below the noise of {:.2e} {} RMS",
                    ex.effect, j.contribution, j.output_unit, j.noise, j.output_unit
                )
            }
        } else {
            format!("the effect of {} is confounded with the other terms{corr}", j.name)
        };
        return (false, Some(format!("{rse_text} (limit {limit} %): {why}; {}", ex.remedy)));
    }
    (true, None)
}
