//! The rigid fit's outputs computed while the loop runs, so that their working storage does
//! not grow with the records: each law is re-run on each record once per output
//! ([`hd_ident::drive::simulate::Run`], a few samples of state) and every sample goes
//! straight into `series.parquet` (row groups of [`hd_io::fit_series::SERIES_CHUNK`] rows),
//! into running sums for the scores, into min/max-thinned curves for the plots
//! ([`hd_plot::ThinnedCurve`], at most [`PLOT_BUCKETS`] buckets of four points each) and,
//! for the best law, into the sums of the residual analysis ([`CorrelationSums`], after a
//! first pass for the means) and of the Welch frequency responses ([`Welch`], one segment
//! held). The numbers are those the whole columns gave, summed in the same order.

use super::Outcome;
use super::resid::{Analysis, OutputInfo, add_output};
use hd_ident::drive::frf::Welch;
use hd_ident::drive::residual_analysis::{CorrelationSums, DEFAULT_LAGS, judge};
use hd_ident::drive::score_rule::{RuledScore, ScoreRule};
use hd_ident::drive::simulate::Run;
use hd_ident::drive::{Experiment, FrictionLaw, OutputKind, Score};
use hd_io::fit_series::{SeriesKey, SeriesStream};
use hd_plot::ThinnedCurve;
use std::ops::Range;
use std::path::Path;

/// Buckets of a plotted curve (each keeps its first, lowest, highest and last point: at
/// most four times as many points are drawn).
pub const PLOT_BUCKETS: usize = 2048;

/// The recorded value of output `kind` of `e` at sample `k` (force: `gain` × command).
fn measured(kind: OutputKind, e: &Experiment, gain: f64, k: usize) -> f64 {
    match kind {
        OutputKind::Force => gain * e.command[k],
        OutputKind::Position => e.position[k],
    }
}

/// The simulated value of output `kind` from the loop's command `u` and position `x`.
fn simulated(kind: OutputKind, gain: f64, u: f64, x: f64) -> f64 {
    match kind {
        OutputKind::Force => gain * u,
        OutputKind::Position => x,
    }
}

/// The input the loop is driven by: the command in open loop, the reference in closed.
pub fn input_of<'a>(o: &Outcome, e: &'a Experiment) -> &'a [f64] {
    if o.controller.open_loop.is_some() { &e.command } else { &e.reference }
}

/// [`hd_ident::drive::score`] of the recorded signal `meas` (its `len` samples, iterated
/// twice in order) against a simulation with Σ (measured − simulated)² = `err_ss`.
fn score_from(meas: impl Iterator<Item = f64> + Clone, len: usize, err_ss: f64) -> Score {
    let n = len.max(1) as f64;
    let mean = meas.clone().sum::<f64>() / n;
    let err = err_ss.sqrt();
    let norm: f64 = meas.clone().map(|y| y * y).sum::<f64>().sqrt();
    let spread: f64 = meas.map(|y| (y - mean).powi(2)).sum::<f64>().sqrt();
    Score {
        rel_error: 100.0 * err / norm,
        rmse: err / n.sqrt(),
        fit_percent: 100.0 * (1.0 - err / spread),
    }
}

/// [`ScoreRule::score`] of output `kind` of `e` from the squared errors summed over the
/// rule's samples `range` (`err_rule`) and over every sample (`err_all`).
fn ruled(
    kind: OutputKind,
    e: &Experiment,
    gain: f64,
    range: &Range<usize>,
    (err_rule, err_all): (f64, f64),
) -> RuledScore {
    let meas = |r: Range<usize>| r.map(move |k| measured(kind, e, gain, k));
    let rule = if range.is_empty() {
        Score { rel_error: f64::NAN, rmse: f64::NAN, fit_percent: f64::NAN }
    } else {
        score_from(meas(range.clone()), range.len(), err_rule)
    };
    RuledScore { rule, all: score_from(meas(0..e.len()), e.len(), err_all), samples: range.len() }
}

/// One output of the best law on one record, as its pass over the record leaves it: the
/// thinned curves to plot (measured, simulated, residual; when plotted) and Σ residual
/// over the scored samples (for the residual analysis's mean).
pub struct OutputTrace {
    /// Measured, simulated and residual against time, thinned.
    pub curves: Option<[ThinnedCurve; 3]>,
    /// Σ (measured − simulated) over the scored samples.
    pub residual_sum: f64,
}

/// What a pass of one law over one output of one record feeds besides the scores.
pub struct Feed<'s, 'a, 'f> {
    /// The series file.
    pub series: &'s mut SeriesStream<'a, 'f>,
    /// Its key (record, set, model, output, unit).
    pub key: SeriesKey,
    /// Whether to keep the thinned curves and the residual sum (the best law).
    pub trace: Option<bool>,
}

/// Run `law` with `values` on `e` once for output `kind`: every sample into the series,
/// the squared errors summed for the rule's samples and for all; returns the scores and,
/// if asked, the output's trace.
pub fn output_pass(
    o: &Outcome,
    rule: &ScoreRule,
    (law, values): (FrictionLaw, &[f64]),
    e: &Experiment,
    kind: OutputKind,
    feed: Feed,
) -> (RuledScore, Option<OutputTrace>) {
    let range = rule.range(e.len());
    feed.series.begin(&feed.key);
    // -0.0: where `Iterator::sum` starts, so the sums are the whole columns' bit for bit.
    let (mut err_rule, mut err_all, mut residual_sum) = (-0.0, -0.0, -0.0);
    let mut curves = match feed.trace {
        Some(true) => Some([(); 3].map(|_| ThinnedCurve::new(PLOT_BUCKETS))),
        _ => None,
    };
    for (k, (u, x)) in Run::new(law, values, &o.controller, e).enumerate() {
        let y = measured(kind, e, o.gain, k);
        let s = simulated(kind, o.gain, u, x);
        let d = y - s;
        let sq = d.powi(2);
        err_all += sq;
        let scored = range.contains(&k);
        if scored {
            err_rule += sq;
            residual_sum += d;
        }
        feed.series.push(k, e.t[k], y, s, scored);
        if let Some([m, sim, r]) = curves.as_mut() {
            m.push(e.t[k], y);
            sim.push(e.t[k], s);
            r.push(e.t[k], d);
        }
    }
    let score = ruled(kind, e, o.gain, &range, (err_rule, err_all));
    (score, feed.trace.map(|_| OutputTrace { curves, residual_sum }))
}

/// The scores of `law` with `values` on `e` (every output, one pass), by `rule`.
pub fn scores(
    o: &Outcome,
    rule: &ScoreRule,
    (law, values): (FrictionLaw, &[f64]),
    e: &Experiment,
) -> Vec<(OutputKind, RuledScore)> {
    let range = rule.range(e.len());
    let kinds: Vec<OutputKind> = o.outputs.iter().map(|x| x.0).collect();
    let mut err = vec![(-0.0, -0.0); kinds.len()];
    for (k, (u, x)) in Run::new(law, values, &o.controller, e).enumerate() {
        let scored = range.contains(&k);
        for (acc, &kind) in err.iter_mut().zip(&kinds) {
            let sq = (measured(kind, e, o.gain, k) - simulated(kind, o.gain, u, x)).powi(2);
            acc.1 += sq;
            if scored {
                acc.0 += sq;
            }
        }
    }
    kinds
        .iter()
        .zip(err)
        .map(|(&kind, sums)| (kind, ruled(kind, e, o.gain, &range, sums)))
        .collect()
}

/// The residual analysis and frequency responses of the best law (`law`, `values`) on
/// `e` over the samples `rule` scores, from a second pass: `traces` are the first passes'
/// (one per output, in the order of the outcome's outputs). Figures and lines go to `a`.
#[allow(clippy::too_many_arguments)]
pub fn analyse_pass(
    a: &mut Analysis,
    dir: &Path,
    prefix: &str,
    o: &Outcome,
    rule: &ScoreRule,
    (law, values): (FrictionLaw, &[f64]),
    e: &Experiment,
    traces: &[OutputTrace],
) -> anyhow::Result<()> {
    let range = rule.range(e.len());
    let n = range.len();
    let input = input_of(o, e);
    let mean_u = input[range.clone()].iter().sum::<f64>() / n.max(1) as f64;
    let kinds: Vec<OutputKind> = o.outputs.iter().map(|x| x.0).collect();
    let mut sums: Vec<CorrelationSums> = traces
        .iter()
        .map(|t| CorrelationSums::new(DEFAULT_LAGS, mean_u, t.residual_sum / n.max(1) as f64))
        .collect();
    // Measured and simulated of each output, in that order.
    let mut welch = Welch::new(n, 2 * kinds.len(), e.h, None);
    let mut ys = vec![0.0; 2 * kinds.len()];
    for (k, (u, x)) in Run::new(law, values, &o.controller, e).enumerate() {
        if !range.contains(&k) {
            continue;
        }
        for (j, &kind) in kinds.iter().enumerate() {
            let (y, s) = (measured(kind, e, o.gain, k), simulated(kind, o.gain, u, x));
            sums[j].push(input[k], y - s);
            ys[2 * j] = y;
            ys[2 * j + 1] = s;
        }
        welch.push(input[k], &ys);
    }
    let frfs = welch.finish();
    let open = o.controller.open_loop.is_some();
    let input_name = if open { "command" } else { "reference" };
    let input_unit = if open { "V" } else { o.axis.position_unit() };
    for (j, &kind) in kinds.iter().enumerate() {
        let (auto, cross) = sums[j].finish();
        let r = judge(auto, cross, input_name);
        let info = OutputInfo {
            experiment: &e.name,
            model: law.name(),
            input: (input_name, input_unit),
            output: (kind.name(), super::unit_of(o.axis, kind)),
        };
        add_output(a, dir, prefix, &info, (r, n), (&frfs[2 * j], &frfs[2 * j + 1]))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use hd_ident::drive::{Axis, Controller};
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    thread_local! {
        static LIVE: Cell<isize> = const { Cell::new(0) };
        static PEAK: Cell<isize> = const { Cell::new(0) };
    }

    fn track(delta: isize) {
        // try_with: no panic while the thread's locals are being torn down.
        let _ = LIVE.try_with(|l| {
            let v = l.get() + delta;
            l.set(v);
            let _ = PEAK.try_with(|p| p.set(p.get().max(v)));
        });
    }

    /// The system allocator, counting this thread's live heap bytes and their peak.
    struct Counting;

    // SAFETY: every call is forwarded to System unchanged; only counters are updated.
    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            // SAFETY: forwarded with the caller's layout.
            let p = unsafe { System.alloc(layout) };
            if !p.is_null() {
                track(layout.size() as isize);
            }
            p
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            // SAFETY: ptr was allocated by System with this layout.
            unsafe { System.dealloc(ptr, layout) };
            track(-(layout.size() as isize));
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            // SAFETY: ptr was allocated by System with this layout.
            let p = unsafe { System.realloc(ptr, layout, new_size) };
            if !p.is_null() {
                track(new_size as isize - layout.size() as isize);
            }
            p
        }
    }

    #[global_allocator]
    static COUNTING: Counting = Counting;

    /// Peak heap bytes `f` holds on this thread above what was live when it started [B].
    fn peak_bytes<R>(f: impl FnOnce() -> R) -> (R, isize) {
        let base = LIVE.with(Cell::get);
        PEAK.with(|p| p.set(base));
        let r = f();
        (r, PEAK.with(Cell::get) - base)
    }

    const P: [f64; 5] = [2.0, 20.0, 5.0, 0.1, 35.0];

    /// An EMPS-like closed loop of `n` samples at 1 kHz, and the outcome around it.
    fn outcome(n: usize) -> Outcome {
        let h = 1e-3;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
        let reference: Vec<f64> = t.iter().map(|t| 0.1 * (3.0 * t).sin()).collect();
        let position: Vec<f64> = t.iter().map(|t| 0.1 * (3.0 * t - 0.01).sin()).collect();
        let command: Vec<f64> = t.iter().map(|t| (3.0 * t).cos()).collect();
        let e = Experiment::new("estimation", "test", t, position, reference, command, Vec::new())
            .unwrap();
        let controller = Controller {
            kp: 160.0,
            kv: 243.0,
            saturation: 10.0,
            delay: 1,
            speed_filter: vec![0.5, 0.5],
            h,
            open_loop: None,
        };
        Outcome {
            config: "test.toml".into(),
            axis: Axis::Linear,
            gain: 35.0,
            controller,
            checks: Vec::new(),
            doubt: Vec::new(),
            disturbance: Vec::new(),
            outputs: vec![(OutputKind::Force, 0.1), (OutputKind::Position, 1e-6)],
            experiments: vec![e],
            validation: None,
            starts: Vec::new(),
            fitted: Vec::new(),
        }
    }

    /// The series, scores and plotted curves of one law on one record (every output).
    fn first_passes(o: &Outcome, path: &Path) -> Vec<OutputTrace> {
        let e = &o.experiments[0];
        let rule = ScoreRule::default();
        hd_io::fit_series::stream_fit_series(path, "force: N, position: m", |st| {
            let mut traces = Vec::new();
            for &(kind, _) in &o.outputs {
                let key = SeriesKey { output: kind.name().into(), ..SeriesKey::default() };
                let feed = Feed { series: st, key, trace: Some(true) };
                let law = (FrictionLaw::CoulombViscous, &P[..]);
                traces.extend(output_pass(o, &rule, law, e, kind, feed).1);
            }
            traces
        })
        .unwrap()
    }

    /// The output stage's working storage does not grow with the record: the series,
    /// scores and thinned curves of 280 000 samples peak within 256 kB of those of 70 000
    /// (both fill a row group of the series; the columns held whole took 210 000 × 2
    /// outputs × about 100 B = 42 MB more), and the residual analysis holds about one
    /// Welch segment, not the record.
    #[test]
    fn output_stage_storage_does_not_grow_with_the_record() {
        let dir = tempfile::tempdir().unwrap();
        let rule = ScoreRule::default();
        let mut peaks = Vec::new();
        for n in [70_000, 280_000] {
            let o = outcome(n);
            let path = dir.path().join(format!("series-{n}.parquet"));
            let (traces, first) = peak_bytes(|| first_passes(&o, &path));
            let e = &o.experiments[0];
            let law = (FrictionLaw::CoulombViscous, &P[..]);
            let (r, second) = peak_bytes(|| {
                let mut a = Analysis {
                    figs: Vec::new(),
                    lines: Vec::new(),
                    json: serde_json::Value::Object(Default::default()),
                };
                analyse_pass(&mut a, dir.path(), "", &o, &rule, law, e, &traces).map(|_| a)
            });
            let a = r.unwrap();
            assert_eq!(a.lines.len(), 2, "{:?}", a.lines);
            let m = hd_ident::drive::frf::default_segment(n) as isize;
            assert!(second < 160 * m + (2 << 20), "{n} samples: analysis peak {second} B");
            peaks.push(first);
        }
        assert!(peaks[1] - peaks[0] < 256 << 10, "first passes' peaks {peaks:?} B");
    }
}
