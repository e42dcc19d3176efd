//! What a voltage test of the compliant drive determines, beyond the Jacobian's null
//! directions and inseparable pairs ([`crate::drive::identifiability`]): a parameter whose
//! 95 % interval (± 2 standard errors) reaches zero is not determined, and when
//! the load inertia Jz is not determined the motor inertia Jj is determined only together
//! with the load's reflected inertia Jz/N² (below the gear's resonance the two move as one
//! inertia Jj + Jz/N²).

use super::fit::CompliantFit;
use super::model::{NAMES, ix};

/// Update `sentences` and `determined` ([`NAMES`] order) from the fitted `values` and
/// their standard errors; `n` is the gear ratio, `rho_jj_jz` the correlation of Jj and Jz.
pub fn refine(
    sentences: &mut Vec<String>,
    values: &[f64; 18],
    std_errors: &[Option<f64>; 18],
    determined: &mut [bool; 18],
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
    if jz_free && !determined[ix::JZ] && std_errors[ix::JJ].is_some() {
        let n2 = n * n;
        let total = values[ix::JJ] + values[ix::JZ] / n2;
        // Var(Jj + Jz/N²) = Var Jj + Var Jz/N⁴ + 2ρ·σJj·σJz/N².
        let (sj, sz) = (std_errors[ix::JJ].unwrap_or(0.0), std_errors[ix::JZ].unwrap_or(0.0));
        let var = sj * sj + sz * sz / (n2 * n2) + 2.0 * rho_jj_jz.unwrap_or(0.0) * sj * sz / n2;
        added.push(format!(
            "Jj is determined only with the load's reflected inertia: Jj + Jz/N² = {total:.5e} ± {:.2e} kg·m² (Jz is not determined, so Jj alone is not either).",
            var.max(0.0).sqrt()
        ));
        determined[ix::JJ] = false;
    }
    if determined[ix::KE] != determined[ix::KM] && std_errors[ix::KM] == std_errors[ix::KE] {
        determined[ix::KM] = determined[ix::KE];
    }
    stiffness_rule(&mut added, values, std_errors, determined, n, corr);
    if !added.is_empty() {
        sentences.retain(|s| !s.starts_with("Every free parameter is determined"));
        sentences.extend(added);
    }
}

/// The gear's spring and memory act together: at a frequency ω the memory adds the storage
/// stiffness A·ω²/(B² + ω²) to the spring's c, so a record that does not separate them
/// determines only their sum near the frequencies it excites. When any of c, mem_A, mem_B
/// is free and not determined, all three are reported as not determined, with the
/// dynamic stiffness K(ω) = c + A·ω²/(B² + ω²) at the load's resonance ω = √(K(ω)/J)
/// (J = Jz·N²Jj/(Jz + N²Jj), found by a few fixed-point steps) and its standard error
/// (delta method).
fn stiffness_rule(
    added: &mut Vec<String>,
    values: &[f64; 18],
    std_errors: &[Option<f64>; 18],
    determined: &mut [bool; 18],
    n: f64,
    corr: &dyn Fn(usize, usize) -> Option<f64>,
) {
    let group = [ix::C, ix::MEM_A, ix::MEM_B];
    let free: Vec<usize> = group.into_iter().filter(|&k| std_errors[k].is_some()).collect();
    if free.is_empty() || free.iter().all(|&k| determined[k]) {
        return;
    }
    let (c, a, b) = (values[ix::C], values[ix::MEM_A], values[ix::MEM_B]);
    let j_motor = values[ix::JJ] * n * n;
    let j = values[ix::JZ] * j_motor / (values[ix::JZ] + j_motor);
    let k_at = |w: f64| c + a * w * w / (b * b + w * w);
    let mut w = ((c + a) / j).sqrt();
    for _ in 0..20 {
        w = (k_at(w) / j).max(0.0).sqrt();
    }
    let w2 = w * w;
    let grad = [1.0, w2 / (b * b + w2), -2.0 * a * b * w2 / (b * b + w2).powi(2)];
    let mut var = 0.0;
    for (i, &p) in group.iter().enumerate() {
        for (l, &q) in group.iter().enumerate() {
            let (Some(sp), Some(sq)) = (std_errors[p], std_errors[q]) else { continue };
            let r = if p == q { 1.0 } else { corr(p, q).unwrap_or(0.0) };
            var += grad[i] * grad[l] * r * sp * sq;
        }
    }
    let names: Vec<&str> = free.iter().map(|&k| NAMES[k]).collect();
    added.push(format!(
        "The spring and the memory ({}) are determined only together: the gear's stiffness at the load's resonance ({:.1} Hz) is K = c + A·ω²/(B² + ω²) = {:.4e} ± {:.2e} N·m/rad.",
        names.join(", "),
        w / std::f64::consts::TAU,
        k_at(w),
        var.max(0.0).sqrt()
    ));
    for k in free {
        determined[k] = false;
    }
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
