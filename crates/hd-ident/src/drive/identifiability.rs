//! What a record determines: standard errors and correlations from the Jacobian at the
//! optimum, and sentences naming the parameter combinations it does not determine.
//!
//! The combinations come from the Jacobian taken with respect to the logarithms of the
//! parameters (relative changes), columns scaled to unit norm: a singular value below
//! [`NULL_TOLERANCE`] of the largest is a direction of relative changes that leaves every
//! output unchanged, which is reported with its weights; a pair of parameters whose
//! correlation reaches [`CORRELATION_LIMIT`] in magnitude is reported as not separable.

use crate::uncertainty::{Covariance, covariance, covariance_rows};
use nalgebra::DMatrix;

/// Relative singular value below which a direction counts as undetermined.
pub const NULL_TOLERANCE: f64 = 1e-7;

/// Correlation magnitude from which two parameters count as not separable.
pub const CORRELATION_LIMIT: f64 = 0.99;

/// Standard errors, correlations and the verdict in words.
#[derive(Clone, Debug, PartialEq)]
pub struct Determination {
    /// Standard error per free parameter (None where it is undetermined).
    pub std_errors: Vec<Option<f64>>,
    /// Correlation matrix of the free parameters.
    pub correlation: Vec<Vec<Option<f64>>>,
    /// One sentence per undetermined combination or inseparable pair; a single sentence
    /// saying every parameter is determined otherwise.
    pub sentences: Vec<String>,
    /// Whether every free parameter is determined.
    pub all_determined: bool,
    /// Per free parameter: whether it is determined (neither in an undetermined combination
    /// nor in a pair that is not separable).
    pub determined: Vec<bool>,
    /// Each undetermined combination: its members (free-parameter slots) with their relative
    /// weights, the largest ±1.
    pub null_directions: Vec<Vec<(usize, f64)>>,
}

fn join(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [a] => a.to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// Determination of the free parameters `names` at `values` from the Jacobian `jac`
/// (∂residual/∂parameter, n × k) and the residual sum of squares `rss`.
pub fn determination(
    jac: &DMatrix<f64>,
    rss: f64,
    names: &[&str],
    values: &[f64],
) -> Determination {
    let k = names.len();
    if k > 0 && !crate::linear::all_finite(jac) {
        return not_finite(k);
    }
    let cols: Vec<Vec<f64>> = (0..k).map(|j| jac.column(j).iter().copied().collect()).collect();
    let cov = covariance(&cols, rss);
    judge(cov, (k > 0 && jac.nrows() >= k).then_some(jac), names, values)
}

/// [`determination`] from the triangular factor `r` (k × k) of the Jacobian's QR
/// factorisation (RᵀR = JᵀJ, as [`crate::qr_stream::StreamingQr`] builds it without holding
/// the Jacobian) and the number of residuals `n`: the same standard errors, correlations
/// and combinations, since R has the Jacobian's column norms, singular values and right
/// singular vectors.
pub fn determination_r(
    r: &DMatrix<f64>,
    n: usize,
    rss: f64,
    names: &[&str],
    values: &[f64],
) -> Determination {
    let k = names.len();
    if k > 0 && (!crate::linear::all_finite(r) || r.ncols() != k) {
        return not_finite(k);
    }
    let mut row = vec![0.0; k];
    let cov = covariance_rows(k, n, rss, &mut |f: &mut dyn FnMut(&[f64])| {
        for i in 0..r.nrows() {
            row.iter_mut().zip(r.row(i).iter()).for_each(|(a, b)| *a = *b);
            f(&row);
        }
        Ok(())
    });
    match cov {
        Ok(cov) => judge(cov, (k > 0 && n >= k).then_some(r), names, values),
        Err(_) => not_finite(k),
    }
}

/// The verdict from the covariance `cov` and, where there are at least as many rows as
/// parameters, a matrix `m` with the Jacobian's column norms and right singular vectors
/// (the Jacobian itself or its R factor), whose relative, unit-norm columns give the
/// undetermined combinations.
fn judge(
    cov: Covariance,
    m: Option<&DMatrix<f64>>,
    names: &[&str],
    values: &[f64],
) -> Determination {
    let k = names.len();
    let mut sentences = Vec::new();
    let mut in_null = vec![false; k];
    let mut null_directions = Vec::new();
    if let Some(jac) = m {
        // Relative sensitivities, unit-norm columns.
        let scale: Vec<f64> =
            (0..k).map(|j| if values[j] != 0.0 { values[j].abs() } else { 1.0 }).collect();
        let mut js = jac.clone();
        let mut norms = vec![0.0; k];
        for j in 0..k {
            let mut c = js.column_mut(j);
            c *= scale[j];
            norms[j] = c.norm();
            if norms[j] > 0.0 {
                c /= norms[j];
            }
        }
        if let Some(svd) = crate::linear::bounded_svd(js, false, true)
            && let Some(vt) = svd.v_t
        {
            let s = &svd.singular_values;
            let smax = s.max();
            for (i, &si) in s.iter().enumerate() {
                if si > NULL_TOLERANCE * smax {
                    continue;
                }
                // Relative change of each parameter along this direction.
                let rel: Vec<f64> = (0..k)
                    .map(|j| if norms[j] > 0.0 { vt[(i, j)] / norms[j] } else { vt[(i, j)] })
                    .collect();
                let big = rel.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                let members: Vec<usize> = (0..k).filter(|&j| rel[j].abs() > 0.05 * big).collect();
                for &j in &members {
                    in_null[j] = true;
                }
                null_directions.push(members.iter().map(|&j| (j, rel[j] / big)).collect());
                let who: Vec<&str> = members.iter().map(|&j| names[j]).collect();
                let weights: Vec<String> =
                    members.iter().map(|&j| format!("{:+.2}", rel[j] / big)).collect();
                sentences.push(if members.len() == 1 {
                    format!("{} is not determined by this record (the outputs do not depend on it); fix it.", who[0])
                } else {
                    format!(
                        "{} are not separable on this record: changing them together by relative amounts ({}) leaves every output unchanged; fix one of them.",
                        join(&who),
                        weights.join(", ")
                    )
                });
            }
        }
    }
    let mut determined: Vec<bool> = in_null.iter().map(|n| !n).collect();
    for a in 0..k {
        for b in a + 1..k {
            if in_null[a] && in_null[b] {
                continue;
            }
            if let Some(r) = cov.correlation[a][b]
                && r.abs() >= CORRELATION_LIMIT
            {
                determined[a] = false;
                determined[b] = false;
                sentences.push(format!(
                    "{} and {} are not separable on this record (correlation {r:.4}); fix one or add an experiment that moves them differently.",
                    names[a], names[b]
                ));
            }
        }
    }
    let all_determined = sentences.is_empty();
    if all_determined {
        let mut worst = (0.0, "", "");
        for a in 0..k {
            for b in a + 1..k {
                if let Some(r) = cov.correlation[a][b]
                    && r.abs() > worst.0
                {
                    worst = (r.abs(), names[a], names[b]);
                }
            }
        }
        sentences.push(if k > 1 {
            format!(
                "Every free parameter is determined by this record (largest correlation {:.3}, between {} and {}).",
                worst.0, worst.1, worst.2
            )
        } else if k == 1 {
            "Every free parameter is determined by this record.".to_string()
        } else {
            "No parameter is free: the record was only simulated.".to_string()
        });
    }
    let std_errors = (0..k).map(|j| if in_null[j] { None } else { cov.std_error[j] }).collect();
    let std_errors: Vec<Option<f64>> = std_errors;
    for (d, se) in determined.iter_mut().zip(&std_errors) {
        *d &= se.is_some();
    }
    Determination {
        std_errors,
        correlation: cov.correlation,
        sentences,
        all_determined,
        determined,
        null_directions,
    }
}

/// The verdict on a Jacobian holding a NaN or an infinity: nothing determined, said so.
fn not_finite(k: usize) -> Determination {
    Determination {
        std_errors: vec![None; k],
        correlation: vec![vec![None; k]; k],
        sentences: vec![
            "The outputs' sensitivities to the parameters are not finite at this result (the drive could not be simulated near it): no parameter is determined.".into(),
        ],
        all_determined: false,
        determined: vec![false; k],
        null_directions: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = (a·b)·t + c·t²: a and b enter only as a product, so the direction (+1, −1) in
    /// relative changes is null; c is determined.
    #[test]
    fn names_a_product_that_only_enters_together() {
        let t: Vec<f64> = (0..50).map(|k| 0.02 * k as f64).collect();
        let (a, b) = (2.0, 3.0);
        let jac = DMatrix::from_fn(t.len(), 3, |i, j| match j {
            0 => b * t[i],
            1 => a * t[i],
            _ => t[i] * t[i],
        });
        let d = determination(&jac, 1.0, &["a", "b", "c"], &[a, b, 0.5]);
        assert!(!d.all_determined);
        assert_eq!(d.sentences.len(), 1, "{:?}", d.sentences);
        let s = &d.sentences[0];
        assert!(
            s.starts_with("a and b are not separable") && s.contains("(+1.00, -1.00)")
                || s.contains("(-1.00, +1.00)"),
            "{s}"
        );
        assert!(
            d.std_errors[0].is_none() && d.std_errors[1].is_none() && d.std_errors[2].is_some()
        );
    }

    /// A NaN in the Jacobian: nothing determined, at once, in one sentence.
    #[test]
    fn non_finite_jacobian_is_not_determined() {
        let mut jac = DMatrix::from_fn(40, 2, |i, j| if j == 0 { 1.0 } else { (i as f64).sin() });
        jac[(5, 1)] = f64::NAN;
        let d = determination(&jac, 1.0, &["p", "q"], &[1.0, 1.0]);
        assert!(!d.all_determined && d.determined == vec![false, false]);
        assert!(d.sentences[0].contains("not finite"), "{:?}", d.sentences);
    }

    /// Independent columns: everything determined, with the largest correlation named.
    #[test]
    fn independent_columns_are_determined() {
        let jac = DMatrix::from_fn(40, 2, |i, j| if j == 0 { 1.0 } else { (i as f64).sin() });
        let d = determination(&jac, 1.0, &["p", "q"], &[1.0, 1.0]);
        assert!(d.all_determined, "{:?}", d.sentences);
        assert!(d.sentences[0].starts_with("Every free parameter is determined"));
    }
}
