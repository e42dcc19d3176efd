//! The inverse-model start (IDIM-LS, the robotics practice the EMPS description follows):
//! the drive force `g·u` is linear in the dynamic parameters given the motion,
//! `g·u = M·ẍ + Fv·ẋ + Fc·sign(ẋ) + offset`, so they follow by linear least squares once
//! speed and acceleration are estimated from the measured position.
//!
//! Steps: the position is low-passed without lag ([`filtfilt`] of a Butterworth filter),
//! differentiated twice by central differences; every column of the observation matrix and
//! the force are then low-passed alike (the "parallel" filter, which removes the force
//! ripple the controller rejects) and kept one sample in `decimate`; then ordinary least
//! squares, with the usual standard errors σ²(XᵀX)⁻¹. The matrix is never held: its rows
//! are reduced to the triangular factor of its QR factorisation as they come
//! ([`StreamingQr`]), and one filtered column of one experiment at a time is held.

use super::error::DriveError;
use super::filter::{butterworth, central_difference, filtfilt};
use super::model::FrictionLaw;
use super::record::Experiment;
use crate::qr_stream::StreamingQr;
use nalgebra::DVector;

/// Filter settings of the inverse-model start.
#[derive(Clone, Debug, PartialEq)]
pub struct IdimOptions {
    /// Corner of the position filter [Hz].
    pub cutoff_hz: f64,
    /// Order of the Butterworth filters.
    pub order: usize,
    /// Keep one sample in this many after the parallel filter.
    pub decimate: usize,
    /// Corner of the parallel filter [Hz].
    pub decimate_cutoff_hz: f64,
}

impl Default for IdimOptions {
    fn default() -> Self {
        IdimOptions { cutoff_hz: 40.0, order: 4, decimate: 10, decimate_cutoff_hz: 25.0 }
    }
}

/// Result of the inverse-model least squares.
#[derive(Clone, Debug, PartialEq)]
pub struct IdimFit {
    /// Parameter names (the law's, without the gain).
    pub names: Vec<&'static str>,
    /// Estimates [axis units].
    pub values: Vec<f64>,
    /// Standard errors [axis units].
    pub std_errors: Vec<f64>,
    /// ‖y − Xθ‖/‖y‖ on the filtered, decimated force [%].
    pub rel_error_percent: f64,
    /// Condition number of the observation matrix.
    pub condition: f64,
    /// Rows used.
    pub rows: usize,
}

/// Columns of the observation matrix of `law` (the first [`columns`] entries) for speed
/// `v` and acceleration `a`.
fn regressors(law: FrictionLaw, v: f64, a: f64) -> [f64; 5] {
    let (pos, neg) = (v > 0.0, v < 0.0);
    match law {
        FrictionLaw::CoulombViscous | FrictionLaw::LuGre => {
            [a, v, v.signum() * f64::from(pos || neg), 1.0, 0.0]
        }
        FrictionLaw::Directional | FrictionLaw::DirectionalLuGre => [
            a,
            if pos { v } else { 0.0 },
            f64::from(pos),
            if neg { v } else { 0.0 },
            -f64::from(neg),
        ],
    }
}

/// IDIM-LS of `law`'s parameters (all but the gain, which is `gain`) on the experiments;
/// for a LuGre law, of its Coulomb–viscous base ([`FrictionLaw::base`]), the steady part of
/// LuGre that a linear regression reaches.
pub fn idim_ls(
    law: FrictionLaw,
    experiments: &[Experiment],
    gain: f64,
    o: &IdimOptions,
) -> Result<IdimFit, DriveError> {
    let law = law.base();
    let names: Vec<&'static str> = law.names().iter().copied().filter(|n| *n != "gain").collect();
    let p = names.len();
    // The observation matrix with the force as its last column, reduced row block by row
    // block to its triangular factor: memory O(p²) for the matrix, whatever the record's
    // length. Each experiment's columns are built, filtered and decimated one at a time.
    let mut qr = StreamingQr::new(p + 1);
    let mut n = 0usize;
    let mut y_norm2 = 0.0;
    let mut finite = true;
    for e in experiments {
        let fs = 1.0 / e.h;
        for (what, f) in [("cutoff_hz", o.cutoff_hz), ("decimate_cutoff_hz", o.decimate_cutoff_hz)]
        {
            if !(f > 0.0 && f < fs / 2.0) {
                return Err(DriveError::config(
                    "[idim]",
                    format!(
                        "{what} = {f} Hz; expected between 0 and the Nyquist frequency {} Hz of '{}'",
                        fs / 2.0,
                        e.name
                    ),
                ));
            }
        }
        let v =
            central_difference(&filtfilt(&butterworth(o.order, o.cutoff_hz, fs), &e.position), e.h);
        let a = central_difference(&v, e.h);
        // Drop the filters' edge samples, then decimate: the rows kept.
        let edge = (2.0 * fs / o.decimate_cutoff_hz.min(o.cutoff_hz)).ceil() as usize;
        let step = o.decimate.max(1);
        let kept: Vec<usize> = (edge..e.len().saturating_sub(edge)).step_by(step).collect();
        let parallel = butterworth(o.order, o.decimate_cutoff_hz, fs);
        let decimated = |x: Vec<f64>| -> Vec<f64> {
            let f = filtfilt(&parallel, &x);
            kept.iter().map(|&k| f[k]).collect()
        };
        let mut cols: Vec<Vec<f64>> = (0..p)
            .map(|j| decimated(v.iter().zip(&a).map(|(&v, &a)| regressors(law, v, a)[j]).collect()))
            .collect();
        drop((v, a));
        cols.push(decimated(e.command.iter().map(|u| gain * u).collect()));
        let mut row = vec![0.0; p + 1];
        for i in 0..kept.len() {
            for (r, c) in row.iter_mut().zip(&cols) {
                *r = c[i];
            }
            finite &= row.iter().all(|x| x.is_finite());
            y_norm2 += row[p] * row[p];
            qr.push(&row);
        }
        n += kept.len();
    }
    if n <= p {
        return Err(DriveError::Fit(format!(
            "IDIM-LS (the inverse-model start): {n} rows after filtering and decimation; need more than {p}: the records are too short for [start] decimate (and the filter's settling), or lower decimate"
        )));
    }
    if !finite {
        return Err(DriveError::Fit(
            "IDIM-LS: the filtered speeds, accelerations or forces are not finite (a NaN or an infinity in a record, or a [start] filter corner at or above the Nyquist frequency)".into(),
        ));
    }
    // [X y] = Q·R: X's singular values are R₁₁'s, Qᵀy is R's last column, and
    // ‖y − Xθ‖² = ‖Qᵀy − R₁₁θ‖² + R[p][p]².
    let r = qr.finish();
    let r11 = r.view((0, 0), (p, p)).into_owned();
    let qty = DVector::from_iterator(p, (0..p).map(|i| r[(i, p)]));
    let svd = crate::linear::bounded_svd(r11.clone(), true, true).ok_or_else(|| {
        DriveError::Fit("IDIM-LS (the inverse-model start): the least-squares decomposition did not converge (check the records' scales: position_scale, command_scale and gain)".into())
    })?;
    let s = &svd.singular_values;
    let condition = s.max() / s.min();
    let theta = svd
        .solve(&qty, 1e-12 * s.max())
        .map_err(|e| DriveError::Fit(format!("IDIM-LS: least squares failed: {e}")))?;
    let rss = (&qty - &r11 * &theta).norm_squared() + r[(p, p)] * r[(p, p)];
    let sigma2 = rss / (n - p) as f64;
    let info = r11.transpose() * &r11;
    let inv = info
        .try_inverse()
        .ok_or_else(|| DriveError::Fit("IDIM-LS: the observation matrix is singular".into()))?;
    Ok(IdimFit {
        names,
        values: theta.iter().copied().collect(),
        std_errors: (0..p).map(|j| (sigma2 * inv[(j, j)]).sqrt()).collect(),
        rel_error_percent: 100.0 * (rss / y_norm2).sqrt(),
        condition,
        rows: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::tests::{TRUTH, record};
    use nalgebra::DMatrix;

    /// The streamed least squares equals the textbook one on the whole observation matrix
    /// (built here directly: every row, an SVD solve, σ²(XᵀX)⁻¹), for both friction laws
    /// and two experiments of different lengths.
    #[test]
    fn streamed_least_squares_equals_the_whole_matrix_solve() {
        for law in [FrictionLaw::CoulombViscous, FrictionLaw::Directional] {
            let es = [
                record(FrictionLaw::CoulombViscous, &TRUTH, 0, 12_345),
                record(FrictionLaw::CoulombViscous, &TRUTH, 0, 7_001),
            ];
            let o = IdimOptions::default();
            let fit = idim_ls(law, &es, TRUTH[4], &o).unwrap();
            let p = fit.names.len();
            let (mut rows, mut ys) = (Vec::new(), Vec::new());
            for e in &es {
                let fs = 1.0 / e.h;
                let q = filtfilt(&butterworth(o.order, o.cutoff_hz, fs), &e.position);
                let v = central_difference(&q, e.h);
                let a = central_difference(&v, e.h);
                let par = butterworth(o.order, o.decimate_cutoff_hz, fs);
                let col = |j: usize| {
                    let x: Vec<f64> =
                        v.iter().zip(&a).map(|(&v, &a)| regressors(law, v, a)[j]).collect();
                    filtfilt(&par, &x)
                };
                let cols: Vec<Vec<f64>> = (0..p).map(col).collect();
                let force =
                    filtfilt(&par, &e.command.iter().map(|u| TRUTH[4] * u).collect::<Vec<_>>());
                let edge = (2.0 * fs / o.decimate_cutoff_hz.min(o.cutoff_hz)).ceil() as usize;
                let mut k = edge;
                while k + edge < e.len() {
                    rows.push((0..p).map(|j| cols[j][k]).collect::<Vec<_>>());
                    ys.push(force[k]);
                    k += o.decimate;
                }
            }
            let n = rows.len();
            assert_eq!(n, fit.rows);
            let x = DMatrix::from_fn(n, p, |i, j| rows[i][j]);
            let y = DVector::from_vec(ys);
            let svd = x.clone().svd(true, true);
            let theta = svd.solve(&y, 1e-12 * svd.singular_values.max()).unwrap();
            let resid = &y - &x * &theta;
            let s2 = resid.norm_squared() / (n - p) as f64;
            let inv = (x.transpose() * &x).try_inverse().unwrap();
            for j in 0..p {
                let (a, b) = (fit.values[j], theta[j]);
                assert!(
                    (a - b).abs() <= 1e-9 * b.abs().max(1e-6),
                    "{law:?} {}: {a} vs {b}",
                    fit.names[j]
                );
                let se = (s2 * inv[(j, j)]).sqrt();
                assert!(
                    (fit.std_errors[j] - se).abs() <= 1e-7 * se,
                    "{}: {} vs {se}",
                    fit.names[j],
                    fit.std_errors[j]
                );
            }
            let rel = 100.0 * resid.norm() / y.norm();
            assert!(
                (fit.rel_error_percent - rel).abs() <= 1e-9 * rel,
                "{} vs {rel}",
                fit.rel_error_percent
            );
            let cond = svd.singular_values.max() / svd.singular_values.min();
            assert!((fit.condition - cond).abs() <= 1e-6 * cond, "{} vs {cond}", fit.condition);
        }
    }
}
