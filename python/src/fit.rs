//! Fits from numpy arrays: `hdw.fit_hysteresis` and `hdw.fit_friction`, the identifiers of
//! `hdw fit hysteresis|friction` without the files. Reports are the fit.json documents.

use crate::errors::{fit_error, value_error};
use hd_ident::stiffness::{Law, LawFit, LawOptions, compare_laws, fit_law};
use hd_ident::{Fixed, FrictionOptions, HysteresisData, SeparableFit, SteadyData, TransientData};
use numpy::{PyArray1, PyArrayLike1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn vec(a: Option<PyArrayLike1<'_, f64>>) -> Option<Vec<f64>> {
    a.map(|a| a.as_array().to_vec())
}

/// `{name: value}` held fixed, checked against the registry.
fn fixed(fix: Option<&Bound<'_, PyDict>>) -> PyResult<Fixed> {
    let mut f = Fixed::none();
    for (k, v) in fix.iter().flat_map(|d| d.iter()) {
        let name: String = k.extract().map_err(|_| value_error("fix: names must be text"))?;
        let value: f64 = v
            .extract()
            .map_err(|_| value_error(format!("fix: '{name}' = {v}: expected a number")))?;
        f.insert(&name, value).map_err(fit_error)?;
    }
    Ok(f)
}

/// `{report: fit.json text, fitted: array, residuals: array}`.
fn fitted(
    py: Python<'_>,
    report: String,
    fitted: Vec<f64>,
    residuals: Vec<f64>,
) -> PyResult<Py<PyDict>> {
    let d = PyDict::new(py);
    d.set_item("report", report)?;
    d.set_item("fitted", PyArray1::from_vec(py, fitted))?;
    d.set_item("residuals", PyArray1::from_vec(py, residuals))?;
    Ok(d.unbind())
}

fn law_dict(py: Python<'_>, fit: LawFit) -> PyResult<Py<PyDict>> {
    fitted(py, fit.report.to_json(), fit.fitted, fit.residuals)
}

/// Fit a stiffness law (`memory`, `maxwell-slip`, `bouc-wen`) to a torque–deflection
/// record, or every law ranked by BIC (`all`: `{comparison: JSON text, fits: {law: …}}`).
#[pyfunction]
#[pyo3(signature = (t, theta, torque, law="memory", elements=None, offset=false, fix=None))]
#[allow(clippy::too_many_arguments)]
pub fn fit_hysteresis(
    py: Python<'_>,
    t: PyArrayLike1<'_, f64>,
    theta: PyArrayLike1<'_, f64>,
    torque: PyArrayLike1<'_, f64>,
    law: &str,
    elements: Option<usize>,
    offset: bool,
    fix: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<PyDict>> {
    // Settings first (as `hdw fit` reads its options before the file), then the data.
    let law = if law == "all" { None } else { Some(Law::parse(law).map_err(fit_error)?) };
    let opts = LawOptions {
        offset,
        elements: elements.unwrap_or(LawOptions::default().elements),
        fixed: fixed(fix)?,
    };
    let data = HysteresisData::new(
        t.as_array().to_vec(),
        theta.as_array().to_vec(),
        torque.as_array().to_vec(),
    )
    .map_err(|e| fit_error(e.into()))?;
    let Some(law) = law else {
        let cmp = py.detach(|| compare_laws(&data, &opts));
        let d = PyDict::new(py);
        d.set_item("comparison", cmp.to_json())?;
        let fits = PyDict::new(py);
        for f in cmp.fits {
            fits.set_item(f.law.name(), law_dict(py, f)?)?;
        }
        d.set_item("fits", fits)?;
        return Ok(d.unbind());
    };
    let fit = py.detach(|| fit_law(&data, law, &opts)).map_err(fit_error)?;
    law_dict(py, fit)
}

fn stage(py: Python<'_>, s: Option<SeparableFit>) -> PyResult<Option<Py<PyDict>>> {
    s.map(|s| fitted(py, s.report.to_json(), s.fitted, s.residuals)).transpose()
}

/// Fit the LuGre parameters: static ones from a steady-state sweep (`steady_omega`,
/// `steady_torque`, optionally `steady_load`), dynamic ones from a time series (`t`,
/// `omega`, `torque`), or both. Returns `{report: fit.json text, steady: …, transient: …}`
/// with each stage's fitted torque and residuals (None for a stage without data).
#[pyfunction]
#[pyo3(signature = (t=None, omega=None, torque=None, steady_omega=None, steady_torque=None, steady_load=None, fix=None, asymmetric=false, offset=false))]
#[allow(clippy::too_many_arguments)]
pub fn fit_friction(
    py: Python<'_>,
    t: Option<PyArrayLike1<'_, f64>>,
    omega: Option<PyArrayLike1<'_, f64>>,
    torque: Option<PyArrayLike1<'_, f64>>,
    steady_omega: Option<PyArrayLike1<'_, f64>>,
    steady_torque: Option<PyArrayLike1<'_, f64>>,
    steady_load: Option<PyArrayLike1<'_, f64>>,
    fix: Option<&Bound<'_, PyDict>>,
    asymmetric: bool,
    offset: bool,
) -> PyResult<Py<PyDict>> {
    let fixed = fixed(fix)?;
    let transient = match (vec(t), vec(omega), vec(torque)) {
        (None, None, None) => None,
        (Some(t), Some(w), Some(q)) => {
            Some(TransientData::new(t, w, q).map_err(|e| fit_error(e.into()))?)
        }
        _ => return Err(value_error("a friction time series needs all of t, omega and torque")),
    };
    let steady = match (vec(steady_omega), vec(steady_torque)) {
        (None, None) => {
            if steady_load.is_some() {
                return Err(value_error("steady: 'load' needs the steady-state omega and torque"));
            }
            None
        }
        (Some(w), Some(q)) => {
            let mut d = SteadyData::new(w, q).map_err(|e| fit_error(e.into()))?;
            if let Some(l) = vec(steady_load) {
                d = d.with_load(l).map_err(|e| fit_error(e.into()))?;
            }
            Some(d)
        }
        _ => return Err(value_error("a steady-state sweep needs both omega and torque")),
    };
    let opts = FrictionOptions { asymmetric, offset: offset || asymmetric };
    let fit = py
        .detach(|| hd_ident::fit_friction_with(steady.as_ref(), transient.as_ref(), &fixed, opts))
        .map_err(fit_error)?;
    let d = PyDict::new(py);
    d.set_item("report", fit.report.to_json())?;
    d.set_item("steady", stage(py, fit.steady)?)?;
    d.set_item("transient", stage(py, fit.transient)?)?;
    Ok(d.unbind())
}
