//! Checks of the spectrum family against closed forms: Schroeder's phases against the
//! crest factor of phases all zero, the weights against the A- and D-optimal shares of two
//! orthogonal elements, and the played sines' information against the sum of each line's
//! alone on a linear drive.

use super::*;
use crate::design::tests::{limits, problem};
use crate::drive::compliant::model::ix;

fn crest(u: &[f64]) -> f64 {
    let peak = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let rms = (u.iter().map(|v| v * v).sum::<f64>() / u.len() as f64).sqrt();
    peak / rms
}

/// Sixteen harmonics of 1 Hz over one second at equal amplitude: with all phases zero the
/// crest factor is √(2·16) = 5.66 (every line peaks at t = 0); with Schroeder's it stays
/// below 2. For amplitudes falling as 1/k it stays below 0.6 of its zero-phase value
/// Σa/√(Σa²/2).
#[test]
fn schroeder_phases_keep_the_peak_low() {
    let t: Vec<f64> = (0..20_000).map(|j| j as f64 / 20_000.0).collect();
    let even: Vec<(f64, f64)> = (1..=16).map(|k| (k as f64, 1.0)).collect();
    let zero: Vec<f64> = t
        .iter()
        .map(|&t| even.iter().map(|(f, a)| a * (std::f64::consts::TAU * f * t).cos()).sum())
        .collect();
    assert!((crest(&zero) - 32f64.sqrt()).abs() < 1e-6, "{}", crest(&zero));
    let c = crest(&Segment::Lines { tones: even }.raw(&t, 1.0));
    assert!(c < 2.0, "{c}");
    let falling: Vec<(f64, f64)> = (1..=16).map(|k| (k as f64, 1.0 / k as f64)).collect();
    let sum: f64 = falling.iter().map(|p| p.1).sum();
    let power: f64 = falling.iter().map(|p| p.1 * p.1).sum();
    let zero = sum / (0.5 * power).sqrt();
    let c = crest(&Segment::Lines { tones: falling }.raw(&t, 1.0));
    assert!(c < 0.6 * zero, "{c} {zero}");
}

/// Two elements each informing one parameter, 4e4 and 1e4 per unit share: the A-optimal
/// share of the first minimises 1/(4e4·w) + 1/(1e4·(1 − w)), w = 1/3; the D-optimal one is
/// 1/2 whatever the sizes (the ridge moves either by under 1e-6).
#[test]
fn weights_reach_the_closed_form_optima() {
    let m1 = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![4e4, 0.0]));
    let m2 = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![0.0, 1e4]));
    let prior = DMatrix::zeros(2, 2);
    let info = [m1, m2];
    let a = weights(&Criterion::A(vec![0, 1]), &prior, &info, 1.0, None);
    assert!((a[0] - 1.0 / 3.0).abs() < 1e-5 && (a[0] + a[1] - 1.0).abs() < 1e-12, "{a:?}");
    let d = weights(&Criterion::D, &prior, &info, 1.0, None);
    assert!((d[0] - 0.5).abs() < 1e-5, "{d:?}");
    // Twice the power halves every variance but leaves the A-optimal shares as they are.
    let a2 = weights(&Criterion::A(vec![0, 1]), &prior, &info, 2.0, None);
    assert!((a2[0] - 1.0 / 3.0).abs() < 1e-5, "{a2:?}");
}

/// The candidates lie on the record's grid k/T, rise, and span 1/T to 0.45 × the rate.
#[test]
fn candidate_lines_lie_on_the_grid() {
    let f = candidate_lines(1000.0, 2.0, 32);
    assert_eq!(f[0], 0.5);
    assert!(*f.last().unwrap() <= 450.0 && *f.last().unwrap() > 400.0, "{f:?}");
    assert!(f.windows(2).all(|w| w[1] > w[0]), "{f:?}");
    assert!(f.iter().all(|x| ((x * 2.0).round() - x * 2.0).abs() < 1e-9), "{f:?}");
    assert!(f.len() > 20, "{f:?}");
}

/// On a drive without friction or cubic spring (linear in its voltage), two grid sines
/// played together carry the sum of each one's information alone on the motor's
/// parameters, each weighted by the square of its share sₖ of its own full-limit amplitude
/// (the power share the family measures). (The gear's, seen through the load's ringing,
/// follow the sum less closely: 8–16 %.)
#[test]
fn sines_together_carry_the_sum_of_their_information() {
    let free = [ix::R, ix::KE, ix::JJ];
    let mut pr = problem(&free, limits(DUR));
    for k in [ix::SIGMA0, ix::SIGMA1, ix::A, ix::B] {
        pr.values[k] = 0.0;
    }
    let crit = Criterion::D;
    let mut tally = Tally { evaluations: 0, best: None, progress: &|_, _| {} };
    let sines = tally.elements(&pr, &crit, vec![sine(20.0), sine(150.0)]);
    assert_eq!(sines.len(), 2);
    let tones = together(&sines, &[0.6, 0.4]);
    let e = evaluate(&pr, &Design::single(Segment::Lines { tones: tones.clone() }), &crit);
    let n = pr.limits.samples();
    let t: Vec<f64> = (0..n).map(|j| j as f64 / pr.limits.rate).collect();
    let raw = Segment::Lines { tones: tones.clone() }.raw(&t, n as f64 / pr.limits.rate);
    let scale = e.scaled.amplitude / raw.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut want = DMatrix::zeros(free.len(), free.len());
    for (s, (_, a)) in sines.iter().zip(&tones) {
        want += &s.info * (scale * a / s.amplitude).powi(2);
    }
    let p = power_reached(&pr, &sines, &tones, &e);
    let share: f64 =
        sines.iter().zip(&tones).map(|(s, (_, a))| (scale * a / s.amplitude).powi(2)).sum();
    assert!((p - share).abs() < 1e-12 * share, "{p} {share}");
    for i in 0..free.len() {
        for j in 0..free.len() {
            let size = (want[(i, i)] * want[(j, j)]).sqrt();
            let (got, w) = (e.info[(i, j)], want[(i, j)]);
            assert!((got - w).abs() <= TOL * size, "{i} {j}: {got} {w}");
        }
    }
}

/// Tolerance of the superposition check, relative to the diagonal: the drive's start from
/// rest (its speed drifts until the mechanical time constant has passed) makes the lines
/// not quite orthogonal; the largest deviation measured is 2.0 % (Ke's diagonal).
const TOL: f64 = 0.1;

/// Length of the superposition check's record [s].
const DUR: f64 = 1.0;

/// On the seed drive over 0.2 s the family's best input is within the limits, no worse
/// than any element alone, and its parameters rebuild it when it is one multisine.
#[test]
fn the_family_beats_every_element_alone() {
    let free = [ix::R, ix::KE, ix::JJ, ix::CJ, ix::JZ, ix::C];
    let pr = problem(&free, limits(0.2));
    let crit = Criterion::A(vec![4, 5]);
    let o = optimise(&pr, &crit, &[], &|_, _| {});
    assert!(o.best.scaled.within, "{:?}", o.best.scaled.peaks);
    let mut tally = Tally { evaluations: 0, best: None, progress: &|_, _| {} };
    let f = candidate_lines(pr.limits.rate, pr.limits.duration, CANDIDATES);
    tally.elements(&pr, &crit, f.into_iter().map(sine).collect());
    tally.elements(&pr, &crit, candidate_ramps(pr.limits.duration));
    let alone = tally.best.unwrap().cost;
    assert!(o.best.cost <= alone, "{} {alone}", o.best.cost);
    assert!(o.evaluations > tally.evaluations, "{} {}", o.evaluations, tally.evaluations);
    if !o.x.is_empty() {
        assert_eq!(Family::Spectrum.design(&o.x), o.best.design);
    }
}
