//! Many runs in parallel: `hdw.simulate_many`. Each parameter set becomes a run of a sweep
//! (hd-sweep's runner: rayon, panics caught) with the GIL released; a run that fails is a
//! row with status `failed` and its error, as in `runs.parquet`.

use crate::config::{config_from_options, param_info};
use crate::errors::value_error;
use crate::table::out_table_dict;
use hd_model::registry::ParamInfo;
use hd_model::{METRICS, SimConfig};
use hd_sweep::axis::Value;
use hd_sweep::study::run_id;
use hd_sweep::tables::runs_table;
use hd_sweep::{RunSpec, run_batch};
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

/// Part name of the runs of a batch (also in their run ids).
const PART: &str = "batch";

/// The metric columns to keep: all, or the names given (each checked).
fn kept_metrics(metrics: Option<Vec<String>>) -> PyResult<Vec<&'static str>> {
    let Some(names) = metrics else { return Ok(METRICS.iter().map(|m| m.name).collect()) };
    names
        .iter()
        .map(|n| {
            METRICS.iter().find(|m| m.name == n).map(|m| m.name).ok_or_else(|| {
                let hint = hd_model::registry::nearest_of(n, METRICS.iter().map(|m| m.name))
                    .map(|s| format!(" (did you mean '{s}'?)"))
                    .unwrap_or_default();
                value_error(format!("metrics: unknown metric '{n}'{hint}"))
            })
        })
        .collect()
}

/// One run of the batch: the base configuration with `values` set (unchecked: a value out
/// of range makes this run fail, not the batch).
fn spec(base: &SimConfig, index: usize, values: &[(&'static ParamInfo, f64)]) -> RunSpec {
    let mut config = base.clone();
    for (info, v) in values {
        info.set_unchecked(&mut config.params, *v);
    }
    RunSpec {
        run_id: run_id(PART, &config),
        index,
        part: PART.into(),
        swept: values.iter().map(|(i, v)| (i.name, Value::Num(*v))).collect(),
        config,
        design: None,
        design_names: Arc::from(Vec::<&'static str>::new()),
    }
}

/// Run `specs` on `threads` threads (default: all cores) with the GIL released, and
/// return the runs table.
fn run_all(
    py: Python<'_>,
    specs: Vec<RunSpec>,
    names: &[&str],
    metrics: Option<Vec<String>>,
    threads: Option<usize>,
) -> PyResult<Py<PyDict>> {
    let keep = kept_metrics(metrics)?;
    if threads == Some(0) {
        return Err(value_error("threads = 0: expected at least 1 thread (or None for all cores)"));
    }
    let pool = match threads {
        Some(n) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| value_error(format!("threads = {n}: {e}")))?,
        ),
        None => None,
    };
    let rows = py.detach(|| {
        let go = || run_batch(&specs, 1, &|_| {}, None);
        match &pool {
            Some(p) => p.install(go),
            None => go(),
        }
    });
    out_table_dict(py, runs_table(&rows, names, &keep))
}

/// Simulate one run per dict of parameters (`{name: value}`, applied over `base`).
#[pyfunction]
#[pyo3(signature = (options, sets, base=None, threads=None, metrics=None))]
pub fn simulate_dicts(
    py: Python<'_>,
    options: &Bound<'_, PyDict>,
    sets: Vec<Bound<'_, PyDict>>,
    base: Option<&Bound<'_, PyDict>>,
    threads: Option<usize>,
    metrics: Option<Vec<String>>,
) -> PyResult<Py<PyDict>> {
    let cfg = config_from_options(options, base, false)?;
    let mut names: Vec<&str> = Vec::new();
    let mut specs = Vec::with_capacity(sets.len());
    for (index, d) in sets.iter().enumerate() {
        let mut values = Vec::with_capacity(d.len());
        for (k, v) in d.iter() {
            let name: String = k.extract().map_err(|_| {
                value_error(format!("parameter set {index}: names must be text, got {k}"))
            })?;
            let info = param_info(&name)
                .map_err(|e| value_error(format!("parameter set {index}: {}", e.value(py))))?;
            let value: f64 = v.extract().map_err(|_| {
                value_error(format!(
                    "parameter set {index}: '{name}' = {v}: expected a number [{}]",
                    info.unit
                ))
            })?;
            if !names.contains(&info.name) {
                names.push(info.name);
            }
            values.push((info, value));
        }
        specs.push(spec(&cfg, index, &values));
    }
    run_all(py, specs, &names, metrics, threads)
}

/// Simulate one run per row of `values` (shape runs × names), column k setting parameter
/// `names[k]` over `base`.
#[pyfunction]
#[pyo3(signature = (options, values, names, base=None, threads=None, metrics=None))]
pub fn simulate_array(
    py: Python<'_>,
    options: &Bound<'_, PyDict>,
    values: PyReadonlyArray2<'_, f64>,
    names: Vec<String>,
    base: Option<&Bound<'_, PyDict>>,
    threads: Option<usize>,
    metrics: Option<Vec<String>>,
) -> PyResult<Py<PyDict>> {
    let cfg = config_from_options(options, base, false)?;
    let a = values.as_array();
    if a.ncols() != names.len() {
        return Err(value_error(format!(
            "values has {} columns but {} names were given: expected one name per column",
            a.ncols(),
            names.len()
        )));
    }
    let infos = names.iter().map(|n| param_info(n)).collect::<PyResult<Vec<_>>>()?;
    for (k, info) in infos.iter().enumerate() {
        if infos[..k].iter().any(|i| i.name == info.name) {
            return Err(value_error(format!("names: parameter '{}' given twice", info.name)));
        }
    }
    let specs: Vec<RunSpec> = a
        .rows()
        .into_iter()
        .enumerate()
        .map(|(index, row)| {
            let values: Vec<_> = infos.iter().copied().zip(row.iter().copied()).collect();
            spec(&cfg, index, &values)
        })
        .collect();
    let names: Vec<&str> = infos.iter().map(|i| i.name).collect();
    run_all(py, specs, &names, metrics, threads)
}
