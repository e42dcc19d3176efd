//! What the rigid and compliant drive fits write beside their scores: the series behind
//! them (`series.parquet`), and for the best model the residual analysis (autocorrelation
//! and cross-correlation with the input against the 99 % white-noise bounds, with a
//! verdict) and the measured and simulated frequency responses from the input to each
//! output (Welch H1), as plots and report lines (docs/fit-drive.md, "Residual analysis").

use crate::cmd::common::staged_plot;
use anyhow::Result;
use hd_ident::drive::frf::{Frf, h1};
use hd_ident::drive::residual_analysis::{DEFAULT_LAGS, ResidualAnalysis, analyse};
use hd_ident::drive::score_rule::ScoreRule;
use hd_io::{FitSeries, SeriesBlock};
use hd_plot::{BodeCurve, Series, bode_plot, line_plot};
use serde_json::{Value, json};
use std::path::Path;

/// One output of a record: recorded and simulated.
pub struct OutputPair {
    /// Output name (`force`, `position`, `motor`, …).
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Recorded values [unit].
    pub measured: Vec<f64>,
    /// Simulated values [unit].
    pub simulated: Vec<f64>,
}

/// One record simulated by one model.
pub struct RecordRun {
    /// Record name.
    pub experiment: String,
    /// `estimation` or `validation`.
    pub set: &'static str,
    /// Model name.
    pub model: String,
    /// Sample times [s].
    pub t: Vec<f64>,
    /// Sample period [s].
    pub h: f64,
    /// Name of the input the simulation is driven by (`reference`, `command`, `voltage`).
    pub input_name: String,
    /// Its unit.
    pub input_unit: String,
    /// The input at each sample [input unit].
    pub input: Vec<f64>,
    /// The outputs compared.
    pub outputs: Vec<OutputPair>,
}

/// Append every output of `run` to `series`, marking the samples `rule` scores.
pub fn add_series(series: &mut FitSeries, run: &RecordRun, rule: &ScoreRule) {
    for o in &run.outputs {
        series.push(SeriesBlock {
            experiment: &run.experiment,
            set: run.set,
            model: &run.model,
            output: &o.name,
            unit: &o.unit,
            t: &run.t,
            measured: &o.measured,
            simulated: &o.simulated,
            scored: rule.range(o.measured.len().min(o.simulated.len())),
        });
    }
}

/// The analysis of one record: figure files, report lines and fit.json's entry.
pub struct Analysis {
    /// Figure file names, in `dir`.
    pub figs: Vec<String>,
    /// One Markdown bullet per output: its verdict and its frequency-response summary.
    pub lines: Vec<String>,
    /// `{output: {verdict, white, …, frequency_response}}`.
    pub json: Value,
}

/// Largest |Δ magnitude| [dB] between two responses over `band`, and where [Hz].
fn largest_gap(meas: &Frf, model: &Frf, band: &[usize]) -> (f64, f64) {
    let (a, b) = (meas.mag_db(), model.mag_db());
    band.iter()
        .filter(|&&k| (a[k] - b[k]).is_finite())
        .map(|&k| ((a[k] - b[k]).abs(), meas.freq[k]))
        .fold((f64::NAN, f64::NAN), |acc, x| if acc.0.is_nan() || x.0 > acc.0 { x } else { acc })
}

fn bode_curve(name: &str, f: &Frf, band: &[usize]) -> BodeCurve {
    let (mag, phase) = (f.mag_db(), f.phase_deg());
    let phase: Vec<f64> = band.iter().map(|&k| phase[k]).collect();
    BodeCurve {
        name: name.into(),
        freq: band.iter().map(|&k| f.freq[k]).collect(),
        mag_db: band.iter().map(|&k| mag[k]).collect(),
        phase_deg: hd_model::metrics::unwrap_deg(&phase),
    }
}

/// What one output's analysis is of: the record, the model, the input and the output.
pub struct OutputInfo<'a> {
    /// Record name.
    pub experiment: &'a str,
    /// Model name.
    pub model: &'a str,
    /// The input's name and unit.
    pub input: (&'a str, &'a str),
    /// The output's name and unit.
    pub output: (&'a str, &'a str),
}

/// The correlation figure of one output: autocorrelation at lags 1 … L, cross-correlation
/// with the input at −L … L, and the ±99 % bounds.
fn correlation_plot(dir: &Path, file: &str, info: &OutputInfo, r: &ResidualAnalysis) -> Result<()> {
    let a = &r.autocorrelation;
    let c = &r.cross_correlation;
    let lags = |l: &[i64]| l.iter().map(|&v| v as f64).collect::<Vec<f64>>();
    let l = DEFAULT_LAGS as f64;
    let curves = [
        Series::new("autocorrelation", lags(&a.lags[1..]), a.values[1..].to_vec()),
        Series::new(
            format!("cross-correlation with the {}", info.input.0),
            lags(&c.lags),
            c.values.clone(),
        ),
        Series::new("99 % bound", vec![-l, l], vec![a.bound; 2]),
        Series::new("−99 % bound", vec![-l, l], vec![-a.bound; 2]),
    ];
    let title = format!(
        "{}: {} residual correlations ({}; {})",
        info.experiment, info.output.0, info.model, r.verdict
    );
    staged_plot(&dir.join(file), |p| {
        line_plot(p, &title, "lag [samples]", "correlation [–]", &curves, false)
    })
}

/// Residual analysis and frequency response of every output of `run` over the samples
/// `rule` scores; figures `prefix resid-<output>.svg` and `prefix bode-<output>.svg`.
pub fn analyse_record(
    dir: &Path,
    prefix: &str,
    run: &RecordRun,
    rule: &ScoreRule,
) -> Result<Analysis> {
    let mut a =
        Analysis { figs: Vec::new(), lines: Vec::new(), json: Value::Object(Default::default()) };
    for o in &run.outputs {
        let n = o.measured.len().min(o.simulated.len()).min(run.input.len());
        let range = rule.range(n);
        let e: Vec<f64> = range.clone().map(|k| o.measured[k] - o.simulated[k]).collect();
        let u = &run.input[range.clone()];
        let r = analyse(u, &e, DEFAULT_LAGS, &run.input_name);
        // Measured and simulated responses from the input, over the input's band.
        let meas = h1(u, &o.measured[range.clone()], run.h, None);
        let model = h1(u, &o.simulated[range.clone()], run.h, None);
        let info = OutputInfo {
            experiment: &run.experiment,
            model: &run.model,
            input: (&run.input_name, &run.input_unit),
            output: (&o.name, &o.unit),
        };
        add_output(&mut a, dir, prefix, &info, (r, e.len()), (&meas, &model))?;
    }
    Ok(a)
}

/// Add one output's analysis to `a`: its residual analysis `r` over `samples` samples and
/// the measured and simulated responses `(meas, model)`, with figures
/// `prefix resid-<output>.svg` and `prefix bode-<output>.svg`.
pub fn add_output(
    a: &mut Analysis,
    dir: &Path,
    prefix: &str,
    info: &OutputInfo,
    (r, samples): (ResidualAnalysis, usize),
    (meas, model): (&Frf, &Frf),
) -> Result<()> {
    let (name, unit) = info.output;
    let file = format!("{prefix}resid-{name}.svg");
    if samples > DEFAULT_LAGS {
        correlation_plot(dir, &file, info, &r)?;
        a.figs.push(file);
    }
    let band = meas.band();
    let (gap, at) = largest_gap(meas, model, &band);
    let (lo, hi) = match (band.first(), band.last()) {
        (Some(&a), Some(&b)) => (meas.freq[a], meas.freq[b]),
        _ => (f64::NAN, f64::NAN),
    };
    let bode = format!("{prefix}bode-{name}.svg");
    if !band.is_empty() {
        let title = format!(
            "{}: {name} over {} [{unit}/{}], measured and {}",
            info.experiment, info.input.0, info.input.1, info.model
        );
        let curves = [bode_curve("measured", meas, &band), bode_curve("model", model, &band)];
        staged_plot(&dir.join(&bode), |p| bode_plot(p, &title, &curves))?;
        a.figs.push(bode.clone());
    }
    let frf_line = if band.is_empty() {
        "no frequency response (record shorter than a segment)".to_string()
    } else {
        format!(
            "frequency response from the {} over {lo:.3}–{hi:.1} Hz: model and measurement differ by at most {gap:.2} dB (at {at:.3} Hz)",
            info.input.0
        )
    };
    a.lines.push(format!("{} {name}: {}; {frf_line}", info.experiment, r.verdict));
    if let Value::Object(doc) = &mut a.json {
        doc.insert(
            name.to_string(),
            json!({
                "verdict": r.verdict,
                "white": r.white,
                "samples": samples,
                "bound": r.autocorrelation.bound,
                "autocorrelation_lags_outside": r.auto_outside,
                "cross_correlation_lags_outside": r.cross_outside,
                "autocorrelation": r.autocorrelation.values,
                "cross_correlation": {"lags": r.cross_correlation.lags, "values": r.cross_correlation.values},
                "input": info.input.0,
                "frequency_response": {
                    "band_hz": [lo, hi],
                    "segment": meas.segment,
                    "largest_db_difference": gap,
                    "at_hz": at,
                },
            }),
        );
    }
    Ok(())
}
