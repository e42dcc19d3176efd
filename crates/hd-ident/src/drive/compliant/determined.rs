//! What a voltage test of the compliant drive determines, beyond the Jacobian's null
//! directions and inseparable pairs ([`crate::drive::identifiability`]): a parameter whose
//! 95 % interval (± 2 standard errors) reaches zero is not determined; when the load
//! inertia Jz is not determined, the motor inertia Jj is determined only together with the
//! load's reflected inertia Jz/N² (below the gear's resonance the two move as one inertia
//! Jj + Jz/N²), and the load's damping and the gear's stiffness only relative to Jz (the
//! record sees Cz/Jz and the resonance); the spring and the memory are reported together,
//! as the load's resonance and the stiffness there.

use super::fit::{CompliantFit, RecordScore, Signal};
use super::model::{NAMES, P, gear_law, ix};
use hd_model::HystLaw;

/// Update `sentences` and `determined` ([`NAMES`] order) from the fitted `values` and
/// their standard errors; `n` is the gear ratio, `rho_jj_jz` the correlation of Jj and Jz.
pub fn refine(
    sentences: &mut Vec<String>,
    values: &[f64; P],
    std_errors: &[Option<f64>; P],
    determined: &mut [bool; P],
    n: f64,
    corr: &dyn Fn(usize, usize) -> Option<f64>,
) {
    let rho_jj_jz = corr(ix::JJ, ix::JZ);
    let mut added = Vec::new();
    for k in 0..NAMES.len() {
        if let Some(se) = std_errors[k]
            && 2.0 * se > values[k].abs()
        {
            let pct = 100.0 * se / values[k].abs().max(f64::MIN_POSITIVE);
            if determined[k] {
                added.push(format!(
                    "{} is not determined by this record: {:.4e} ± {:.2e} (± {pct:.0} %): its 95 % interval reaches zero; fix it or add an experiment that excites it.",
                    NAMES[k], values[k], se
                ));
            }
            determined[k] = false;
        }
    }
    let jz_free = std_errors[ix::JZ].is_some();
    let said = |opening: &str| sentences.iter().any(|s| s.starts_with(opening));
    if jz_free && !determined[ix::JZ] && std_errors[ix::JJ].is_some() && !said(INERTIA_SENTENCE) {
        let n2 = n * n;
        let total = values[ix::JJ] + values[ix::JZ] / n2;
        // Var(Jj + Jz/N²) = Var Jj + Var Jz/N⁴ + 2ρ·σJj·σJz/N².
        let (sj, sz) = (std_errors[ix::JJ].unwrap_or(0.0), std_errors[ix::JZ].unwrap_or(0.0));
        let var = sj * sj + sz * sz / (n2 * n2) + 2.0 * rho_jj_jz.unwrap_or(0.0) * sj * sz / n2;
        added.push(format!(
            "{INERTIA_SENTENCE} the load's reflected inertia: Jj + Jz/N² = {total:.5e} ± {:.2e} kg·m² (Jz is not determined, so Jj alone is not either).",
            var.max(0.0).sqrt()
        ));
        determined[ix::JJ] = false;
    }
    // Jz, Cz and the gear's stiffness scaled together leave the load's motion relative to
    // the motor as it was (its resonance and damping rates are ratios to Jz); only the
    // deflection's small reaction on the motor sees the scale. So where Jz is not
    // determined, neither are Cz, c, mem_A, bw_alpha, ms_k and the catalogue's rates.
    if jz_free && !determined[ix::JZ] {
        if std_errors[ix::CZ].is_some() && determined[ix::CZ] && !said(DAMPING_SENTENCE) {
            let rate = |v: &[f64; P]| v[ix::CZ] / v[ix::JZ];
            let se = delta_se(&rate, values, &[ix::CZ, ix::JZ], std_errors, corr);
            added.push(format!(
                "{DAMPING_SENTENCE} apart from Jz: the record sees the load's damping rate Cz/Jz = {:.4e} ± {se:.2e} 1/s.",
                rate(values)
            ));
        }
        for k in
            [ix::CZ, ix::C, ix::MEM_A, ix::BW_ALPHA, ix::MS_K, ix::CAT_K1, ix::CAT_K2, ix::CAT_K3]
        {
            determined[k] = false;
        }
    }
    if determined[ix::KE] != determined[ix::KM] && std_errors[ix::KM] == std_errors[ix::KE] {
        determined[ix::KM] = determined[ix::KE];
    }
    if !said(stiffness_sentence(values)) {
        stiffness_rule(&mut added, values, std_errors, determined, n, corr);
    }
    if !added.is_empty() {
        sentences.retain(|s| !s.starts_with("Every free parameter is determined"));
        sentences.extend(added);
    }
}

/// The opening of the stiffness rule's sentence for the gear law of `values` (it is added
/// once).
fn stiffness_sentence(values: &[f64; P]) -> &'static str {
    match gear_law(values) {
        HystLaw::BoucWen => "The spring and the Bouc–Wen element",
        HystLaw::MaxwellSlip => "The spring and the slip elements",
        HystLaw::Catalogue => "The catalogue curve's rates",
        _ => "The spring and the memory",
    }
}

/// The opening of the load-damping sentence (it is added once).
const DAMPING_SENTENCE: &str = "Cz is not determined";

/// The opening of the reflected-inertia sentence (it is added once).
const INERTIA_SENTENCE: &str = "Jj is determined only with";

/// The load's resonance ω [rad/s] of the drive at `v` (ratio `n`): the fixed point of
/// ω = √(K(ω)/J), with the memory gear's dynamic stiffness K(ω) = c + A·ω²/(B² + ω²) and
/// the two inertias' reduced inertia J = Jz·N²Jj/(Jz + N²Jj) [kg·m²]. Returns (ω, K(ω)).
pub fn resonance(v: &[f64; P], n: f64) -> (f64, f64) {
    let (c, a, b) = (v[ix::C], v[ix::MEM_A], v[ix::MEM_B]);
    let j_motor = v[ix::JJ] * n * n;
    let j = v[ix::JZ] * j_motor / (v[ix::JZ] + j_motor);
    let k_at = |w: f64| c + a * w * w / (b * b + w * w);
    let mut w = ((c + a) / j).max(0.0).sqrt();
    for _ in 0..60 {
        w = (k_at(w) / j).max(0.0).sqrt();
    }
    (w, k_at(w))
}

/// Standard error of `f(values)` by the delta method over the parameters `which`, from
/// their standard errors and correlations (central differences of `f`, a closed form).
fn delta_se(
    f: &dyn Fn(&[f64; P]) -> f64,
    values: &[f64; P],
    which: &[usize],
    std_errors: &[Option<f64>; P],
    corr: &dyn Fn(usize, usize) -> Option<f64>,
) -> f64 {
    let grad: Vec<f64> = which
        .iter()
        .map(|&k| {
            let h = 1e-6 * values[k].abs().max(f64::MIN_POSITIVE);
            let (mut up, mut down) = (*values, *values);
            up[k] += h;
            down[k] -= h;
            (f(&up) - f(&down)) / (2.0 * h)
        })
        .collect();
    let mut var = 0.0;
    for (i, &p) in which.iter().enumerate() {
        for (l, &q) in which.iter().enumerate() {
            let (Some(sp), Some(sq)) = (std_errors[p], std_errors[q]) else { continue };
            let r = if p == q { 1.0 } else { corr(p, q).unwrap_or(0.0) };
            var += grad[i] * grad[l] * r * sp * sq;
        }
    }
    var.max(0.0).sqrt()
}

/// The gear's spring and memory act together: at a frequency ω the memory adds the storage
/// stiffness A·ω²/(B² + ω²) to the spring's c, so a record that does not separate them
/// determines their sum only near the frequencies it excites. When any of c, mem_A, mem_B
/// is free and not determined, all three are reported as not determined, with the load's
/// resonance frequency ([`resonance`]) and the dynamic stiffness K there, each with its
/// standard error (delta method). When the load inertia Jz is not determined either, the
/// sentence says that the record sees the ratio K/J (the resonance), not K: scaling Jz, Cz
/// and the gear's stiffness together changes the load's motion only through the small
/// torque of the deflection's acceleration on the motor.
fn stiffness_rule(
    added: &mut Vec<String>,
    values: &[f64; P],
    std_errors: &[Option<f64>; P],
    determined: &mut [bool; P],
    n: f64,
    corr: &dyn Fn(usize, usize) -> Option<f64>,
) {
    let law = gear_law(values);
    let group: &[usize] = match law {
        HystLaw::BoucWen => &[ix::C, ix::BW_ALPHA],
        HystLaw::MaxwellSlip => &[ix::C, ix::MS_K],
        HystLaw::Catalogue => &[ix::CAT_K1, ix::CAT_K2, ix::CAT_K3],
        _ => &[ix::C, ix::MEM_A, ix::MEM_B],
    };
    let free: Vec<usize> = group.iter().copied().filter(|&k| std_errors[k].is_some()).collect();
    if free.is_empty() || free.iter().all(|&k| determined[k]) {
        return;
    }
    let names: Vec<&str> = free.iter().map(|&k| NAMES[k]).collect();
    let jz_seen = std_errors[ix::JZ].is_none() || determined[ix::JZ];
    let what = format!(
        "{} ({}) are determined only together",
        stiffness_sentence(values),
        names.join(", ")
    );
    let sentence = if law != HystLaw::Memory {
        // A rate-independent element's share of the stiffness depends on how far it is
        // deflected (it saturates, or its elements slip): no single resonance frequency
        // stands for the record, so none is given.
        let tail = if jz_seen {
            ""
        } else {
            " The load inertia Jz is not determined either, and the record sees the gear's stiffness only relative to it."
        };
        let why = if law == HystLaw::Catalogue {
            "each rate holds only over its segment of the curve, and this record does not deflect the gear far enough on each side of the corners to tell them apart"
        } else {
            "the element's share of the gear's stiffness depends on how far it is deflected, and this record does not separate it from the spring's"
        };
        format!("{what}: {why}.{tail}")
    } else {
        let which = [ix::JJ, ix::JZ, ix::C, ix::MEM_A, ix::MEM_B];
        let hz = |v: &[f64; P]| resonance(v, n).0 / std::f64::consts::TAU;
        let stiffness = |v: &[f64; P]| resonance(v, n).1;
        let (f, se_f) = (hz(values), delta_se(&hz, values, &which, std_errors, corr));
        let (k, se_k) = (stiffness(values), delta_se(&stiffness, values, &which, std_errors, corr));
        let tail = if jz_seen {
            ""
        } else {
            " The load inertia Jz is not determined, and the record sees the stiffness only relative to it (the resonance): K holds at the fitted Jz, and scales with it."
        };
        format!(
            "{what}: the load resonates at {} Hz, where the gear's stiffness is K = c + A·ω²/(B² + ω²) = {k:.4e} ± {se_k:.2e} N·m/rad.{tail}",
            with_se(f, se_f)
        )
    };
    added.push(sentence);
    for k in free {
        determined[k] = false;
    }
}

/// Run [`refine`]'s rules again on a fit whose `determined` changed after it was made (the
/// agreement of rival fits): each rule adds its sentence once.
pub fn refine_fit(fit: &mut CompliantFit, n: f64) {
    let det = &fit.determination;
    let params = fit.jacobian_params.clone();
    let correlation = det.correlation.clone();
    let corr = |a: usize, b: usize| {
        let (sa, sb) = (params.iter().position(|&k| k == a)?, params.iter().position(|&k| k == b)?);
        correlation[sa][sb]
    };
    let mut sentences = std::mem::take(&mut fit.determination.sentences);
    refine(&mut sentences, &fit.values, &fit.std_errors, &mut fit.determined, n, &corr);
    fit.determination.sentences = sentences;
    fit.determination.all_determined = params.iter().all(|&k| fit.determined[k]);
}

/// Mark as not determined every parameter of `best` on which one of `rivals` (fits whose
/// cost is within the profile threshold of the best's) differs by more than twice the
/// best fit's standard error, with one sentence each giving the range the fits span.
pub fn not_determined_by_agreement(best: &mut CompliantFit, rivals: &[&CompliantFit]) {
    let mut added = Vec::new();
    for (k, name) in NAMES.iter().enumerate() {
        let Some(se) = best.std_errors[k] else { continue };
        let v = best.values[k];
        let apart: Vec<f64> =
            rivals.iter().map(|r| r.values[k]).filter(|&w| (w - v).abs() > 2.0 * se).collect();
        if apart.is_empty() {
            continue;
        }
        let lo = apart.iter().copied().fold(v, f64::min);
        let hi = apart.iter().copied().fold(v, f64::max);
        added.push(format!(
            "{} is not determined by this record: fits that match it as well as the best (cost within the 95 % profile threshold) put it anywhere from {lo:.4e} to {hi:.4e}; its standard error ± {se:.2e} holds only near the best fit.",
            name
        ));
        best.determined[k] = false;
    }
    if !added.is_empty() {
        let d = &mut best.determination;
        d.sentences.retain(|s| !s.starts_with("Every free parameter is determined"));
        d.sentences.extend(added);
        d.all_determined = false;
    }
}

/// Ratio of an output's residual RMS to its given noise level above which the fit is said
/// not to reach the noise (a good fit sits near 1; the tests ask ≤ 1.2).
pub const MISFIT_RATIO: f64 = 1.5;

/// One sentence per output of `fit` whose residuals stay above [`MISFIT_RATIO`] times its
/// noise level: one the configuration gave (`given(output)`), or one estimated from the
/// record itself (its third differences; the fit keeps that level where its residuals stay
/// far above it, [`super::stages`], so a level the misfit set is never called the noise).
/// The standard errors assume the residuals are the noise, so every value is in doubt.
pub fn misfit_sentences(fit: &CompliantFit, given: impl Fn(Signal) -> bool) -> Vec<String> {
    let mut out = Vec::new();
    for score in &fit.scores {
        for (o, sc, level, ratio) in &score.outputs {
            if *ratio > MISFIT_RATIO {
                let whose = if given(*o) {
                    "the level given"
                } else {
                    "the noise level the record itself shows (its third differences, which if anything overstate it)"
                };
                out.push(format!(
                    "The fit does not reach the noise on {}'s {}: its residual RMS {:.3e} is {ratio:.2} times {whose}, {level:.3e}. The standard errors assume the residuals are the noise, so every value below, determined or not, is in doubt.",
                    score.name,
                    o.name(),
                    sc.rmse
                ));
            }
        }
    }
    out
}

/// Put `fit` in doubt where it calls every free parameter determined and still misses a
/// validation record's noise: each output of `validation` whose residuals stay above
/// [`MISFIT_RATIO`] times its level while the fitted records' stay at or below it. A drive
/// the records pin down in every direction predicts any record of it within its standard
/// errors, so such a miss is a local optimum (or a model that lacks what the validation
/// record shows), not an input the records did not excite: that one leaves a parameter
/// undetermined, and then this rule does not speak. Returns the sentences added (the first
/// of the determination's, and `fit.doubt`).
pub fn doubt_from_validation(fit: &mut CompliantFit, validation: &RecordScore) -> Vec<String> {
    // Every parameter with a standard error determined, none held for want of one (a
    // symmetric law's negative-side levels follow its own and carry no verdict).
    let all_determined = fit.held.is_empty()
        && (0..NAMES.len())
            .filter(|&k| fit.free[k] && fit.std_errors[k].is_some())
            .all(|k| fit.determined[k]);
    if !fit.doubt.is_empty() || !all_determined {
        return Vec::new();
    }
    let fitted = |o: Signal| {
        fit.scores
            .iter()
            .filter_map(|s| s.outputs.iter().find(|x| x.0 == o).map(|x| x.3))
            .fold(0.0, f64::max)
    };
    let missed: Vec<(Signal, f64)> = validation
        .outputs
        .iter()
        .filter(|(o, _, _, ratio)| *ratio > MISFIT_RATIO && fitted(*o) <= MISFIT_RATIO)
        .map(|(o, _, _, ratio)| (*o, *ratio))
        .collect();
    let list = |f: &dyn Fn(&(Signal, f64)) -> String| {
        let items: Vec<String> = missed.iter().map(f).collect();
        match items.len() {
            0 | 1 => items.concat(),
            n => format!("{} and {}", items[..n - 1].join(", "), items[n - 1]),
        }
    };
    let added: Vec<String> = if missed.is_empty() {
        Vec::new()
    } else {
        vec![format!(
            "Every free parameter is called determined by the fitted records, yet the fit predicts the validation record's {} at {} times the noise (the fitted records' at {}): a drive the records pin down would predict it within its standard errors. The fit has likely ended at a local optimum (or the model lacks what the validation record shows), so every value below is in doubt; try other starts, or fit the validation record with the others.",
            list(&|(o, _)| o.name().to_string()),
            list(&|(_, r)| format!("{r:.2}")),
            list(&|(o, _)| format!("{:.2}", fitted(*o))),
        )]
    };
    put_in_doubt(fit, added.clone());
    added
}

/// Put `fit` in doubt for `reasons`, said first: before its other reasons and before every
/// sentence of what the records determine (which then no longer says all are). Nothing
/// changes when `reasons` is empty.
pub fn put_in_doubt(fit: &mut CompliantFit, reasons: Vec<String>) {
    if reasons.is_empty() {
        return;
    }
    let d = &mut fit.determination;
    d.sentences.retain(|s| !s.starts_with("Every free parameter is determined"));
    d.sentences.splice(0..0, reasons.iter().cloned());
    d.all_determined = false;
    fit.doubt.splice(0..0, reasons);
}

/// `v ± se` with as many decimals as the standard error's two significant digits need, or
/// `v (standard error undetermined)` where there is none.
pub fn with_se(v: f64, se: f64) -> String {
    if !(se > 0.0 && se.is_finite()) {
        return format!("{v:.4} (its standard error undetermined)");
    }
    let decimals = (1 - se.log10().floor() as i64).clamp(0, 12) as usize;
    format!("{v:.decimals$} ± {se:.decimals$}")
}
