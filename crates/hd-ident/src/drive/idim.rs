//! The inverse-model start (IDIM-LS, the robotics practice the EMPS description follows):
//! the drive force `g·u` is linear in the dynamic parameters given the motion,
//! `g·u = M·ẍ + Fv·ẋ + Fc·sign(ẋ) + offset`, so they follow by linear least squares once
//! speed and acceleration are estimated from the measured position.
//!
//! Steps: the position is low-passed without lag ([`filtfilt`] of a Butterworth filter),
//! differentiated twice by central differences; every column of the observation matrix and
//! the force are then low-passed alike (the "parallel" filter, which removes the force
//! ripple the controller rejects) and kept one sample in `decimate`; then ordinary least
//! squares, with the usual standard errors σ²(XᵀX)⁻¹.

use super::error::DriveError;
use super::filter::{butterworth, central_difference, filtfilt};
use super::model::FrictionLaw;
use super::record::Experiment;
use nalgebra::{DMatrix, DVector};

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

/// Rows of the observation matrix of `law` for speed `v` and acceleration `a`.
fn regressors(law: FrictionLaw, v: f64, a: f64) -> Vec<f64> {
    let (pos, neg) = (v > 0.0, v < 0.0);
    match law {
        FrictionLaw::CoulombViscous | FrictionLaw::LuGre => {
            vec![a, v, v.signum() * f64::from(pos || neg), 1.0]
        }
        FrictionLaw::Directional | FrictionLaw::DirectionalLuGre => vec![
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
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut ys: Vec<f64> = Vec::new();
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
        let q = filtfilt(&butterworth(o.order, o.cutoff_hz, fs), &e.position);
        let v = central_difference(&q, e.h);
        let a = central_difference(&v, e.h);
        let x: Vec<Vec<f64>> = v.iter().zip(&a).map(|(&v, &a)| regressors(law, v, a)).collect();
        let parallel = butterworth(o.order, o.decimate_cutoff_hz, fs);
        let mut cols: Vec<Vec<f64>> = (0..p)
            .map(|j| filtfilt(&parallel, &x.iter().map(|r| r[j]).collect::<Vec<_>>()))
            .collect();
        let force: Vec<f64> = e.command.iter().map(|u| gain * u).collect();
        cols.push(filtfilt(&parallel, &force));
        // Drop the filters' edge samples, then decimate.
        let edge = (2.0 * fs / o.decimate_cutoff_hz.min(o.cutoff_hz)).ceil() as usize;
        let step = o.decimate.max(1);
        let mut k = edge;
        while k + edge < e.len() {
            rows.push((0..p).map(|j| cols[j][k]).collect());
            ys.push(cols[p][k]);
            k += step;
        }
    }
    let n = rows.len();
    if n <= p {
        return Err(DriveError::Fit(format!(
            "IDIM-LS: {n} rows after filtering and decimation; need more than {p}"
        )));
    }
    let x = DMatrix::from_fn(n, p, |i, j| rows[i][j]);
    let y = DVector::from_vec(ys);
    if !crate::linear::all_finite(&x) || y.iter().any(|v| !v.is_finite()) {
        return Err(DriveError::Fit(
            "IDIM-LS: the filtered speeds, accelerations or forces are not finite (a NaN or an infinity in a record, or a [start] filter corner at or above the Nyquist frequency)".into(),
        ));
    }
    let svd = crate::linear::bounded_svd(x.clone(), true, true).ok_or_else(|| {
        DriveError::Fit("IDIM-LS: the least-squares decomposition did not converge".into())
    })?;
    let s = &svd.singular_values;
    let condition = s.max() / s.min();
    let theta = svd
        .solve(&y, 1e-12 * s.max())
        .map_err(|e| DriveError::Fit(format!("IDIM-LS: least squares failed: {e}")))?;
    let resid = &y - &x * &theta;
    let rss = resid.norm_squared();
    let sigma2 = rss / (n - p) as f64;
    let info = x.transpose() * &x;
    let inv = info
        .try_inverse()
        .ok_or_else(|| DriveError::Fit("IDIM-LS: the observation matrix is singular".into()))?;
    Ok(IdimFit {
        names,
        values: theta.iter().copied().collect(),
        std_errors: (0..p).map(|j| (sigma2 * inv[(j, j)]).sqrt()).collect(),
        rel_error_percent: 100.0 * resid.norm() / y.norm(),
        condition,
        rows: n,
    })
}
