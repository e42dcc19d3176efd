//! A study file run in-process: `hdw.run_study`. The same checker, expansion, runner and
//! table builder as `hdw study`; writing the tables is left to the Python side.

use crate::errors::value_error;
use crate::table::out_table_dict;
use hd_model::Profile;
use hd_sweep::tables::{runs_table, traces_table};
use hd_sweep::{RunStatus, StudyManifest, load_study, run_batch};
use numpy::PyArrayLike1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// Run the study file at `path`. `read_profile(path) -> (t, u)` reads a recorded input a
/// study names; `parts` keeps only the named parts; `threads` (default all cores) sizes the
/// pool. Returns a dict: `name`, `runs` (the runs table's columns), `traces` (long-format
/// trace columns, or None when the study keeps no traces), `manifest` (study.json's
/// content as JSON text) and `failed` (how many runs failed).
#[pyfunction]
#[pyo3(signature = (path, read_profile, threads=None, parts=None))]
pub fn run_study(
    py: Python<'_>,
    path: PathBuf,
    read_profile: Bound<'_, PyAny>,
    threads: Option<usize>,
    parts: Option<Vec<String>>,
) -> PyResult<Py<PyDict>> {
    let loader = |p: &Path| -> Result<Profile, String> {
        let (t, u): (PyArrayLike1<f64>, PyArrayLike1<f64>) = read_profile
            .call1((p.to_path_buf(),))
            .and_then(|r| r.extract())
            .map_err(|e| e.to_string())?;
        Profile::new(t.as_array().to_vec(), u.as_array().to_vec(), &p.display().to_string())
            .map_err(|e| e.to_string())
    };
    let mut study = load_study(&path, &loader).map_err(|e| value_error(e.to_string()))?;
    if let Some(names) = &parts {
        for name in names {
            if !study.parts.iter().any(|p| &p.name == name) {
                let known: Vec<&str> = study.parts.iter().map(|p| p.name.as_str()).collect();
                return Err(value_error(format!(
                    "parts: no part '{name}' in {} (parts: {})",
                    path.display(),
                    known.join(", ")
                )));
            }
        }
        study.parts.retain(|p| names.contains(&p.name));
        study.compare.retain(|c| names.contains(&c.part));
    }
    if threads == Some(0) {
        return Err(value_error("threads = 0: expected at least 1 thread (or None for all cores)"));
    }
    let runs = study.expand();
    let manifest = StudyManifest::new(&study, &runs, None, env!("CARGO_PKG_VERSION"));
    let manifest = serde_json::to_string_pretty(&manifest)
        .map_err(|e| value_error(format!("study.json: {e}")))?;
    let decimate = study.traces.decimate;
    let rows = py.detach(|| -> Result<_, String> {
        let go = || run_batch(&runs, decimate, &|_| {});
        match threads {
            Some(n) => Ok(rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| e.to_string())?
                .install(go)),
            None => Ok(go()),
        }
    });
    let rows = rows.map_err(|e| value_error(format!("threads: {e}")))?;
    let failed = rows.iter().filter(|r| r.status != RunStatus::Ok).count();
    let swept = study.swept_names();
    let traces = rows.iter().any(|r| r.trace.is_some()).then(|| traces_table(&rows));
    let d = PyDict::new(py);
    d.set_item("name", &study.name)?;
    d.set_item("runs", out_table_dict(py, runs_table(&rows, &swept, &study.keep_metrics))?)?;
    match traces {
        Some(t) => d.set_item("traces", out_table_dict(py, t)?)?,
        None => d.set_item("traces", py.None())?,
    }
    d.set_item("manifest", manifest)?;
    d.set_item("failed", failed)?;
    Ok(d.unbind())
}
