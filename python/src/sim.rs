//! One run: `hdw.simulate`.

use crate::config::config_from_options;
use crate::errors::sim_error;
use crate::table::trace_dict;
use hd_model::{SimOutput, simulate as run};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Simulate one run. `options` holds the run settings (see `config_from_options`),
/// `params` the parameters that differ from the defaults. Returns a dict with `trace`
/// (columns, or None), `metrics` ({name: value}, NaN where undefined), `solver` (the
/// `solver` object of metrics.json), `parameters` (every parameter used) and `config`
/// (the full configuration as JSON text).
#[pyfunction]
#[pyo3(signature = (options, params=None, trace=true))]
pub fn simulate(
    py: Python<'_>,
    options: &Bound<'_, PyDict>,
    params: Option<&Bound<'_, PyDict>>,
    trace: bool,
) -> PyResult<Py<PyDict>> {
    let cfg = config_from_options(options, params, trace)?;
    let out: SimOutput = py.detach(|| run(&cfg)).map_err(sim_error)?;
    let d = PyDict::new(py);
    match out.trace {
        Some(t) => d.set_item("trace", trace_dict(py, t)?)?,
        None => d.set_item("trace", py.None())?,
    }
    let metrics = PyDict::new(py);
    for (k, v) in out.metrics.to_pairs() {
        metrics.set_item(k, v)?;
    }
    d.set_item("metrics", metrics)?;
    let s = &out.stats;
    let solver = PyDict::new(py);
    solver.set_item("method", s.method.name())?;
    solver.set_item("rtol", cfg.solver.rtol)?;
    solver.set_item("atol", cfg.solver.atol)?;
    solver.set_item("steps", s.steps)?;
    solver.set_item("rejected_steps", s.rejected)?;
    solver.set_item("rhs_evaluations", s.rhs_evals)?;
    solver.set_item("jacobian_evaluations", s.jac_evals)?;
    solver.set_item("lu_decompositions", s.lu_decomps)?;
    solver.set_item("implicit_steps", s.implicit_steps)?;
    solver.set_item("method_switches", s.switches)?;
    solver.set_item("wall_time_s", out.wall_time)?;
    d.set_item("solver", solver)?;
    let params = PyDict::new(py);
    for (k, v) in cfg.params.to_pairs() {
        params.set_item(k, v)?;
    }
    d.set_item("parameters", params)?;
    let json = serde_json::to_string(&cfg)
        .map_err(|e| crate::errors::value_error(format!("configuration: {e}")))?;
    d.set_item("config", json)?;
    Ok(d.unbind())
}
