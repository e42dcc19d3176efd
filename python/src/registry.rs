//! The parameter registry, the metric names and the column documentation, for Python.

use hd_model::registry::{ParamInfo, REGISTRY};
use hd_model::{METRICS, schema};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The parameter registry as columns: name, unit, default, min, max, min_inclusive,
/// range (as error messages write it), aliases (comma-separated) and description.
#[pyfunction]
pub fn parameters(py: Python<'_>) -> PyResult<Py<PyDict>> {
    let text = |f: &dyn Fn(&ParamInfo) -> String| REGISTRY.iter().map(f).collect::<Vec<_>>();
    let num = |f: &dyn Fn(&ParamInfo) -> f64| {
        PyArray1::from_vec(py, REGISTRY.iter().map(f).collect::<Vec<_>>())
    };
    let d = PyDict::new(py);
    d.set_item("name", text(&|p| p.name.to_string()))?;
    d.set_item("unit", text(&|p| p.unit.to_string()))?;
    d.set_item("default", num(&|p| p.default_value()))?;
    d.set_item("min", num(&|p| p.min))?;
    d.set_item("max", num(&|p| p.max))?;
    d.set_item("min_inclusive", REGISTRY.iter().map(|p| p.min_inclusive).collect::<Vec<_>>())?;
    d.set_item("range", text(&|p| p.range_text()))?;
    d.set_item("aliases", text(&|p| p.aliases.join(",")))?;
    d.set_item("description", text(&|p| p.doc.to_string()))?;
    Ok(d.unbind())
}

/// Every metric name, in output order.
#[pyfunction]
pub fn metric_names() -> Vec<&'static str> {
    METRICS.iter().map(|m| m.name).collect()
}

/// Unit and description of an output column (as written to Parquet field metadata), or
/// None for a name the schema does not document.
#[pyfunction]
pub fn column_doc(name: &str) -> Option<(&'static str, String)> {
    schema::describe(name).map(|c| (c.unit, c.doc.to_string()))
}
