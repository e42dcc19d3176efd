//! Tables handed to Python: a dict of columns in output order. Numbers become numpy arrays
//! (the vectors are moved into numpy, not copied), text and optional cells become lists.

use hd_model::{Cells, OutTable, TRACE_COLUMNS, Trace};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The columns of `t` as `{name: column}`: `F64` → float64 array (NaN where undefined),
/// `U64` → uint64 array, optional counts → list of int or None, text → list of str (or None).
pub fn out_table_dict(py: Python<'_>, t: OutTable) -> PyResult<Py<PyDict>> {
    let d = PyDict::new(py);
    for c in t.columns {
        match c.cells {
            Cells::F64(v) => d.set_item(c.name, PyArray1::from_vec(py, v))?,
            Cells::U64(v) => d.set_item(c.name, PyArray1::from_vec(py, v))?,
            Cells::OptU64(v) => d.set_item(c.name, v)?,
            Cells::Text(v) => d.set_item(c.name, v)?,
            Cells::OptText(v) => d.set_item(c.name, v)?,
        }
    }
    Ok(d.unbind())
}

/// A run's trace as `{column: float64 array}` in `trace.parquet` order.
pub fn trace_dict(py: Python<'_>, mut trace: Trace) -> PyResult<Py<PyDict>> {
    let d = PyDict::new(py);
    for c in TRACE_COLUMNS {
        let v = std::mem::take(c.of_mut(&mut trace));
        d.set_item(c.name, PyArray1::from_vec(py, v))?;
    }
    Ok(d.unbind())
}
