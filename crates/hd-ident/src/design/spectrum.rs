//! The spectrum family: an input built from chosen elementary tests, the classical optimal
//! design over a candidate set.
//!
//! The elements are sines (log-spaced over the band, on the record's frequency grid k/T)
//! and slow ramps with and without dwell. Each is played alone over the whole record,
//! scaled to the limits, and its information Mₖ taken from the fit's exact Jacobian
//! ([`super::search::evaluate`]). Two ways of playing chosen elements are then weighed,
//! each a weighting w of the simplex minimising the criterion of M₀ + P·Σ wₖ·Mₖ (convex for
//! the D-, A- and log-variance criteria; solved by exponentiated gradient, [`weights`]):
//!
//! - **one after another** (a stepped sine with ramps): element k for the share wₖ of the
//!   time at its own full-limit amplitude carries about wₖ·Mₖ, so P = 1 and ramps take part;
//!   an element too short to show itself (a sine under two periods, a ramp under one) is
//!   dropped and the weights solved again;
//! - **together** (a multisine of the chosen sines with Schroeder's phases for their uneven
//!   powers): line k at the share sₖ of its full-limit amplitude carries about sₖ²·Mₖ over
//!   the whole record, and its peak allows Σ sₖ² ≤ P, the crest factor's doing; P is
//!   measured on each played candidate and the weights solved again.
//!
//! The linear picture only proposes: every played input is scaled to the limits exactly and
//! judged by its own exact information, like any other family's candidate. A second round
//! adds sines between the chosen ones and their neighbours.

use super::criterion::Criterion;
use super::info::Problem;
use super::input::{Design, Family, Piece, Segment};
use super::search::{Evaluated, Optimised, evaluate};
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Candidate sines of the first round [–].
pub const CANDIDATES: usize = 32;

/// Rounds of measuring the power share P of the sines played together and solving the
/// weights again [–].
const ROUNDS: usize = 3;

/// An element's weight below this share of the largest is dropped [–].
const DROP: f64 = 1e-3;

/// Candidate frequencies [Hz] for a record of `duration` [s] at `rate` [Hz]: `count`
/// log-spaced from 1/duration to 0.45·rate, each on the grid k/duration, without repeats.
pub fn candidate_lines(rate: f64, duration: f64, count: usize) -> Vec<f64> {
    let df = 1.0 / duration;
    let (lo, hi) = (df, (0.45 * rate).max(2.0 * df));
    let count = count.max(2);
    let mut f: Vec<f64> = (0..count)
        .map(|k| lo * (hi / lo).powf(k as f64 / (count - 1) as f64))
        .map(|f| (f / df).round().max(1.0) * df)
        .filter(|&f| f <= hi)
        .collect();
    f.dedup_by(|a, b| (*a - *b).abs() < 0.5 * df);
    f
}

/// Candidate ramps for a record of `duration` [s]: 2, 4, 8 and 16 periods per record (at
/// most 20 Hz), each without dwell and with a quarter of each half period at zero.
pub fn candidate_ramps(duration: f64) -> Vec<Segment> {
    [2.0, 4.0, 8.0, 16.0]
        .iter()
        .map(|k| k / duration)
        .filter(|&f| f <= 20.0)
        .flat_map(|f| [0.0, 0.25].map(|dwell| Segment::Ramp { f, dwell }))
        .collect()
}

/// An elementary test played alone over the whole record at its full-limit amplitude.
#[derive(Clone, Debug)]
struct Element {
    design: Design,
    amplitude: f64,
    info: DMatrix<f64>,
}

impl Element {
    fn of(e: &Evaluated) -> Element {
        Element { design: e.design.clone(), amplitude: e.scaled.amplitude, info: e.info.clone() }
    }

    /// The sine's frequency [Hz] (None for any other element).
    fn sine(&self) -> Option<f64> {
        match self.design.pieces.as_slice() {
            [Piece { segment: Segment::Lines { tones }, .. }] if tones.len() == 1 => {
                Some(tones[0].0)
            }
            _ => None,
        }
    }

    /// The shortest share of a record of `duration` [s] that still shows the element: two
    /// periods of its slowest sine, chirp or multisine line, one of its slowest ramp, over
    /// each piece's own share; at most 1, the whole record it was judged on [–].
    fn min_share(&self, duration: f64) -> f64 {
        let total: f64 = self.design.pieces.iter().map(|p| p.share.max(0.0)).sum::<f64>();
        self.design
            .pieces
            .iter()
            .map(|p| {
                let (periods, f) = match &p.segment {
                    Segment::Lines { tones } => {
                        (2.0, tones.iter().fold(f64::INFINITY, |m, t| m.min(t.0)))
                    }
                    Segment::Chirp { f0, f1 } => (2.0, f0.min(*f1)),
                    Segment::Multisine { f0, f1, .. } => (2.0, f0.min(*f1)),
                    Segment::Ramp { f, .. } => (1.0, *f),
                };
                let own = p.share.max(0.0) / total.max(f64::MIN_POSITIVE);
                periods / (f * duration * own.max(f64::MIN_POSITIVE))
            })
            .fold(0.0, f64::max)
            .min(1.0)
    }
}

fn sine(f: f64) -> Segment {
    Segment::Lines { tones: vec![(f, 1.0)] }
}

/// The weights on the simplex minimising `criterion` of `prior + power·Σ wₖ·infoₖ`, from
/// `start` (uniform where None): exponentiated gradient with a step that grows while it
/// helps and halves while it does not, the gradient by forward differences of the
/// criterion along each element's information.
pub fn weights(
    criterion: &Criterion,
    prior: &DMatrix<f64>,
    info: &[DMatrix<f64>],
    power: f64,
    start: Option<&[f64]>,
) -> Vec<f64> {
    let k = info.len();
    if k == 0 {
        return Vec::new();
    }
    let total = |w: &[f64]| {
        let mut m = prior.clone();
        for (wk, mk) in w.iter().zip(info) {
            m += mk * (power * wk);
        }
        m
    };
    let mut w: Vec<f64> = match start {
        Some(s) if s.len() == k && s.iter().sum::<f64>() > 0.0 => {
            let sum: f64 = s.iter().sum();
            s.iter().map(|v| (v / sum).max(1e-12)).collect()
        }
        _ => vec![1.0 / k as f64; k],
    };
    let mut m = total(&w);
    let mut cost = criterion.cost(&m);
    let mut eta = 1.0;
    let h = 1e-5;
    for _ in 0..500 {
        if !cost.is_finite() {
            break;
        }
        let g: Vec<f64> =
            info.iter().map(|mk| (criterion.cost(&(&m + mk * (power * h))) - cost) / h).collect();
        let mean: f64 = w.iter().zip(&g).map(|(a, b)| a * b).sum();
        let spread = g.iter().fold(0.0f64, |s, v| s.max((v - mean).abs()));
        if !(spread > 0.0 && spread.is_finite()) {
            break;
        }
        let mut improved = false;
        while eta > 1e-9 {
            let mut next: Vec<f64> =
                w.iter().zip(&g).map(|(a, b)| a * (-eta * (b - mean) / spread).exp()).collect();
            let sum: f64 = next.iter().sum();
            next.iter_mut().for_each(|v| *v /= sum);
            let mn = total(&next);
            let c = criterion.cost(&mn);
            if c < cost {
                improved = (cost - c) > 1e-10 * cost.abs().max(1e-12);
                (w, m, cost) = (next, mn, c);
                eta = (eta * 1.5).min(50.0);
                break;
            }
            eta *= 0.5;
        }
        if !improved {
            break;
        }
    }
    w
}

/// The candidates judged so far: their count and the best.
struct Tally<'a> {
    evaluations: usize,
    best: Option<Evaluated>,
    progress: &'a (dyn Fn(usize, f64) + Sync),
}

impl Tally<'_> {
    fn note(&mut self, e: Evaluated) {
        self.evaluations += 1;
        if self.best.as_ref().is_none_or(|b| e.cost < b.cost) {
            self.best = Some(e);
        }
        (self.progress)(self.evaluations, self.best.as_ref().map_or(f64::INFINITY, |b| b.cost));
    }

    fn judge(&mut self, problem: &Problem, criterion: &Criterion, d: Design) -> Evaluated {
        let e = evaluate(problem, &d, criterion);
        self.note(e.clone());
        e
    }

    /// `segments` played alone (in parallel): those within the limits with a finite
    /// information.
    fn elements(
        &mut self,
        problem: &Problem,
        criterion: &Criterion,
        segments: Vec<Segment>,
    ) -> Vec<Element> {
        let judged: Vec<Evaluated> = segments
            .into_par_iter()
            .map(|s| evaluate(problem, &Design::single(s), criterion))
            .collect();
        let kept = judged.iter().filter(|e| usable(e)).map(Element::of).collect();
        judged.into_iter().for_each(|e| self.note(e));
        kept
    }
}

/// Whether a candidate played alone can be an element: within the limits, with a finite
/// information.
fn usable(e: &Evaluated) -> bool {
    e.scaled.within && e.scaled.amplitude > 0.0 && e.info.iter().all(|v| v.is_finite())
}

fn infos(elements: &[Element]) -> Vec<DMatrix<f64>> {
    elements.iter().map(|e| e.info.clone()).collect()
}

/// The largest of `v` (0 for an empty or all-negative slice: weights and amplitudes).
fn largest(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(*x))
}

/// The largest magnitude in `v` (a signal's peak) [its unit].
fn largest_magnitude(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The sines of `sines` weighted by `w` played together: line k at amplitude ∝ its
/// full-limit amplitude times √wₖ (weights below [`DROP`] of the largest dropped).
fn together(sines: &[Element], w: &[f64]) -> Vec<(f64, f64)> {
    let top = largest(w);
    sines
        .iter()
        .zip(w)
        .filter(|(_, wk)| **wk >= DROP * top && **wk > 0.0)
        .filter_map(|(e, wk)| e.sine().map(|f| (f, e.amplitude * wk.sqrt())))
        .collect()
}

/// The power share P the played `tones` reach once scaled to the amplitude of `e`: Σ sₖ²
/// with sₖ line k's amplitude over its own full-limit amplitude.
fn power_reached(problem: &Problem, sines: &[Element], tones: &[(f64, f64)], e: &Evaluated) -> f64 {
    let n = problem.limits.samples();
    let rate = problem.limits.rate;
    let t: Vec<f64> = (0..n).map(|j| j as f64 / rate).collect();
    let raw = Segment::Lines { tones: tones.to_vec() }.raw(&t, n as f64 / rate);
    let peak = largest_magnitude(&raw).max(f64::MIN_POSITIVE);
    let scale = e.scaled.amplitude / peak;
    tones
        .iter()
        .map(|(f, a)| {
            let full =
                sines.iter().find(|s| s.sine() == Some(*f)).map_or(f64::INFINITY, |s| s.amplitude);
            (scale * a / full).powi(2)
        })
        .sum()
}

/// The sines played together: weights solved, played, P measured, at most [`ROUNDS`] times
/// (until P settles within 5 %). Returns the weights reached.
fn settle_together(
    problem: &Problem,
    criterion: &Criterion,
    sines: &[Element],
    start: Option<Vec<f64>>,
    tally: &mut Tally,
) -> Vec<f64> {
    let info = infos(sines);
    let mut w = start;
    let mut power = 1.0;
    for _ in 0..ROUNDS {
        let wk = weights(criterion, &problem.prior, &info, power, w.as_deref());
        let tones = together(sines, &wk);
        let e = tally.judge(
            problem,
            criterion,
            Design::single(Segment::Lines { tones: tones.clone() }),
        );
        let reached = power_reached(problem, sines, &tones, &e);
        w = Some(wk);
        if !(reached.is_finite() && reached > 0.0) {
            break;
        }
        let change = (reached / power - 1.0).abs();
        power = reached;
        if change < 0.05 {
            break;
        }
    }
    w.unwrap_or_default()
}

/// The elements played one after another: weights solved as time shares (P = 1); those
/// too short to show themselves ([`Element::min_share`]) or below [`DROP`] dropped and the
/// rest solved again, until every kept one is long enough; then played (ramps first, then
/// the sines in rising frequency, each at its own full-limit amplitude). Returns the share
/// of every element (zero where dropped).
fn one_after_another(
    problem: &Problem,
    criterion: &Criterion,
    elements: &[Element],
    tally: &mut Tally,
) -> Vec<f64> {
    let duration = problem.limits.duration;
    let mut kept: Vec<usize> = (0..elements.len()).collect();
    let mut w: Option<Vec<f64>> = None;
    for _ in 0..4 * elements.len() {
        let info: Vec<DMatrix<f64>> = kept.iter().map(|&i| elements[i].info.clone()).collect();
        let wk = weights(criterion, &problem.prior, &info, 1.0, w.as_deref());
        let top = largest(&wk);
        // How far each kept element is from long enough (below 1: too short).
        let ratio: Vec<f64> = kept
            .iter()
            .zip(&wk)
            .map(|(&i, &v)| if v < DROP * top { 0.0 } else { v / elements[i].min_share(duration) })
            .collect();
        let mut short: Vec<usize> = (0..kept.len()).filter(|&j| ratio[j] < 1.0).collect();
        if short.is_empty() || short.len() == kept.len() {
            w = Some(wk);
            break;
        }
        // Drop the shortest quarter of the short ones, and solve again from where it was.
        short.sort_by(|&a, &b| ratio[a].total_cmp(&ratio[b]));
        short.truncate(short.len().div_ceil(4));
        let (next, nw): (Vec<usize>, Vec<f64>) =
            (0..kept.len()).filter(|j| !short.contains(j)).map(|j| (kept[j], wk[j])).unzip();
        kept = next;
        w = Some(nw);
    }
    let w = w.unwrap_or_default();
    let mut share = vec![0.0; elements.len()];
    let top = largest(&w);
    for (&i, &wk) in kept.iter().zip(&w) {
        if wk >= DROP * top {
            share[i] = wk;
        }
    }
    let loudest = elements
        .iter()
        .zip(&share)
        .filter(|(_, s)| **s > 0.0)
        .fold(0.0f64, |m, (e, _)| m.max(e.amplitude));
    let mut order: Vec<usize> = (0..elements.len()).filter(|&i| share[i] > 0.0).collect();
    order.sort_by(|&a, &b| {
        let key = |i: usize| elements[i].sine().unwrap_or(0.0);
        key(a).total_cmp(&key(b))
    });
    let mut pieces: Vec<Piece> = Vec::new();
    for &i in &order {
        let e = &elements[i];
        let own: f64 = e.design.pieces.iter().map(|p| p.share.max(0.0)).sum::<f64>();
        let top = e.design.pieces.iter().fold(0.0f64, |m, p| m.max(p.weight)).max(1e-12);
        let level = e.amplitude / loudest.max(f64::MIN_POSITIVE);
        pieces.extend(e.design.pieces.iter().map(|p| Piece {
            segment: p.segment.clone(),
            share: share[i] * p.share.max(0.0) / own.max(f64::MIN_POSITIVE),
            weight: level * p.weight / top,
        }));
    }
    if !pieces.is_empty() {
        tally.judge(problem, criterion, Design { pieces });
    }
    share
}

/// Grid frequencies [Hz] between each sine of weight ≥ 1 % of the largest and its
/// neighbours (geometric means, on the grid of `df` [Hz]), not already among `sines`.
fn between(sines: &[Element], w: &[f64], df: f64) -> Vec<f64> {
    let top = largest(w);
    let f: Vec<f64> = sines.iter().filter_map(Element::sine).collect();
    let mut extra: Vec<f64> = Vec::new();
    for (i, &fi) in f.iter().enumerate() {
        if w[i] < 0.01 * top {
            continue;
        }
        for nb in [i.checked_sub(1), Some(i + 1)].into_iter().flatten().filter_map(|j| f.get(j)) {
            let mid = ((fi * nb).sqrt() / df).round() * df;
            let taken = |g: f64| (g - mid).abs() < 0.5 * df;
            if !f.iter().any(|&o| taken(o)) && !extra.iter().any(|&o| taken(o)) {
                extra.push(mid);
            }
        }
    }
    extra
}

/// Choose the input for `problem` by `criterion` from the elementary tests and the best
/// inputs of the families already searched (`others`, each a candidate element too);
/// `progress(evaluations, best cost)` after each evaluation. [`CANDIDATES`] sines and
/// [`candidate_ramps`] played alone, the sines between the chosen ones and their neighbours
/// in a second round, and a few played inputs per round.
pub fn optimise(
    problem: &Problem,
    criterion: &Criterion,
    others: &[&Evaluated],
    progress: &(dyn Fn(usize, f64) + Sync),
) -> Optimised {
    let (rate, duration) = (problem.limits.rate, problem.limits.duration);
    let mut tally = Tally { evaluations: 0, best: None, progress };
    let lines = candidate_lines(rate, duration, CANDIDATES);
    let mut sines = tally.elements(problem, criterion, lines.into_iter().map(sine).collect());
    let mut rest = tally.elements(problem, criterion, candidate_ramps(duration));
    rest.extend(
        others.iter().filter(|e| usable(e) && !e.design.pieces.is_empty()).map(|e| Element::of(e)),
    );
    for round in 0..2 {
        // An element that needs the whole record to show itself is judged alone, not shared.
        let all: Vec<Element> =
            sines.iter().chain(&rest).filter(|e| e.min_share(duration) < 1.0).cloned().collect();
        let shares = one_after_another(problem, criterion, &all, &mut tally);
        if sines.is_empty() {
            break;
        }
        let w = settle_together(problem, criterion, &sines, None, &mut tally);
        if round == 1 {
            break;
        }
        // Sines between the chosen ones of either way of playing them.
        let df = 1.0 / duration;
        let mut extra = between(&sines, &w, df);
        let (stepped, stepped_w): (Vec<Element>, Vec<f64>) = all
            .iter()
            .zip(&shares)
            .filter(|(e, _)| e.sine().is_some())
            .map(|(e, &w)| (e.clone(), w))
            .unzip();
        for f in between(&stepped, &stepped_w, df) {
            if !extra.iter().any(|&o| (o - f).abs() < 0.5 * df) {
                extra.push(f);
            }
        }
        if extra.is_empty() {
            break;
        }
        sines.extend(tally.elements(problem, criterion, extra.into_iter().map(sine).collect()));
        sines.sort_by(|a, b| a.sine().unwrap_or(0.0).total_cmp(&b.sine().unwrap_or(0.0)));
    }
    let evaluations = tally.evaluations;
    let best = tally.best.expect("at least one candidate was evaluated");
    let x: Vec<f64> = match best.design.pieces.as_slice() {
        [Piece { segment: Segment::Lines { tones }, .. }] => {
            tones.iter().flat_map(|&(f, a)| [f, a]).collect()
        }
        _ => Vec::new(),
    };
    Optimised { family: Family::Spectrum, x, best, evaluations }
}

#[cfg(test)]
mod tests;
