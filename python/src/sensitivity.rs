//! Sobol' indices of outputs from any Saltelli-ordered sample (e.g. SALib's), with the
//! estimators and bootstrap of `hdw sensitivity`: `hdw.sobol_indices`.

use crate::errors::value_error;
use hd_sweep::sensitivity::{SaltelliOutputs, SobolOptions, sobol_indices as estimate};
use numpy::{PyArray1, PyArrayLike1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// First-order and total indices of `y`, the outputs of a Saltelli design of `dims`
/// parameters in row-group order: for each base row, A, A_B^(1) … A_B^(d), B (the order of
/// hdw's designs and of SALib's `sobol.sample(..., calc_second_order=False)`). NaN marks a
/// failed run (its whole base row is dropped). Returns columns S1, S1_lo, S1_hi, ST, ST_lo,
/// ST_hi (one entry per parameter) and n_used, n_dropped, note.
#[pyfunction]
#[pyo3(signature = (y, dims, bootstrap=1000, confidence=0.95, seed=0))]
pub fn sobol_indices(
    py: Python<'_>,
    y: PyArrayLike1<'_, f64>,
    dims: usize,
    bootstrap: usize,
    confidence: f64,
    seed: u64,
) -> PyResult<Py<PyDict>> {
    let y = y.as_array().to_vec();
    let group = dims + 2;
    if dims == 0 || !y.len().is_multiple_of(group) || y.is_empty() {
        return Err(value_error(format!(
            "y has {} values: expected a multiple of dims + 2 = {group} (base rows × (A, {dims} × AB, B))",
            y.len()
        )));
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(value_error(format!("confidence = {confidence}: expected a level in (0, 1)")));
    }
    let n = y.len() / group;
    let at = |j: usize, pos: usize| y[j * group + pos];
    let outputs = SaltelliOutputs {
        a: (0..n).map(|j| at(j, 0)).collect(),
        b: (0..n).map(|j| at(j, dims + 1)).collect(),
        ab: (0..dims).map(|i| (0..n).map(|j| at(j, i + 1)).collect()).collect(),
    };
    let opts = SobolOptions { bootstrap, confidence, seed, ..Default::default() };
    let e = py.detach(|| estimate(&outputs, &opts));
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(usize) -> f64| PyArray1::from_vec(py, (0..dims).map(f).collect());
    d.set_item("S1", col(&|i| e.s1[i].value))?;
    d.set_item("S1_lo", col(&|i| e.s1[i].lo))?;
    d.set_item("S1_hi", col(&|i| e.s1[i].hi))?;
    d.set_item("ST", col(&|i| e.st[i].value))?;
    d.set_item("ST_lo", col(&|i| e.st[i].lo))?;
    d.set_item("ST_hi", col(&|i| e.st[i].hi))?;
    d.set_item("n_used", e.n_used)?;
    d.set_item("n_dropped", e.n_dropped)?;
    d.set_item("note", e.note)?;
    Ok(d.unbind())
}
