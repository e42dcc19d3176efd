//! One run: `hdw.simulate`.

use crate::config::config_from_options;
use crate::errors::sim_error;
use crate::table::trace_dict;
use hd_model::state::{OMEGA_J, OMEGA_Z, State, THETA, THETA_J};
use hd_model::{DriveSystem, SimOutput, simulate as run, simulate_states};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The trace columns that are states (or the time), read at each grid time without
/// evaluating any other signal ([`simulate_states`]).
const STATE_COLUMNS: [&str; 6] = ["t", "theta_j", "omega_j", "theta_z", "omega_z", "theta"];

fn state_column(name: &str, sys: &DriveSystem, t: f64, y: &State) -> f64 {
    match name {
        "t" => t,
        "theta_j" => y[THETA_J],
        "omega_j" => y[OMEGA_J],
        "theta_z" => sys.load_angle(y),
        "omega_z" => y[OMEGA_Z],
        _ => y[THETA],
    }
}

/// Simulate one run. `options` holds the run settings (see `config_from_options`),
/// `params` the parameters that differ from the defaults. Returns a dict with `trace`
/// (columns, or None), `metrics` ({name: value}, NaN where undefined), `solver` (the
/// `solver` object of metrics.json), `parameters` (every parameter used) and `config`
/// (the full configuration as JSON text).
///
/// `states`, when given, names trace columns that are all states or the time (`t`,
/// `theta_j`, `omega_j`, `theta_z`, `omega_z`, `theta`): only those are recorded, read from
/// the solution at each grid time with no other signal evaluated, and `trace` is ignored.
#[pyfunction]
#[pyo3(signature = (options, params=None, trace=true, states=None))]
pub fn simulate(
    py: Python<'_>,
    options: &Bound<'_, PyDict>,
    params: Option<&Bound<'_, PyDict>>,
    trace: bool,
    states: Option<Vec<String>>,
) -> PyResult<Py<PyDict>> {
    if let Some(bad) = states.iter().flatten().find(|n| !STATE_COLUMNS.contains(&n.as_str())) {
        return Err(crate::errors::value_error(format!(
            "columns: '{bad}' is not a state column (expected some of {})",
            STATE_COLUMNS.join(", ")
        )));
    }
    let cfg = config_from_options(options, params, trace && states.is_none())?;
    let d = PyDict::new(py);
    let out: SimOutput = match &states {
        Some(names) => {
            let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
            let out = py
                .detach(|| {
                    simulate_states(&cfg, &mut |sys, t, y| {
                        for (c, n) in cols.iter_mut().zip(names) {
                            c.push(state_column(n, sys, t, y));
                        }
                    })
                })
                .map_err(sim_error)?;
            let columns = PyDict::new(py);
            for (n, c) in names.iter().zip(cols) {
                columns.set_item(n, PyArray1::from_vec(py, c))?;
            }
            d.set_item("trace", columns)?;
            out
        }
        None => {
            let mut out = py.detach(|| run(&cfg)).map_err(sim_error)?;
            match out.trace.take() {
                Some(t) => d.set_item("trace", trace_dict(py, t)?)?,
                None => d.set_item("trace", py.None())?,
            }
            out
        }
    };
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
