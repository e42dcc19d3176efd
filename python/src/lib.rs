//! The compiled half of the `hdw` Python package (`hdw._hdw`): thin bindings over hd-model
//! (one run), hd-sweep (batches and studies) and hd-ident (fits). Numbers cross as numpy
//! arrays, tables as dicts of columns; the Python half (`python/hdw/`) turns those into
//! polars DataFrames when polars is installed. No polars or Parquet code is compiled here.

mod batch;
mod config;
mod cpu_guard;
mod errors;
mod fit;
mod registry;
mod sensitivity;
mod sim;
mod study;
mod table;

use pyo3::prelude::*;

/// The extension module `hdw._hdw`.
#[pymodule]
fn _hdw(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Where the load-time check does not run (not Linux), check here: PyO3's set-up may
    // already have used the build's instructions, but most of a build's are not.
    hd_model::cpu::check().map_err(pyo3::exceptions::PyImportError::new_err)?;
    m.add("SimulationError", m.py().get_type::<errors::SimulationError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(registry::parameters, m)?)?;
    m.add_function(wrap_pyfunction!(registry::metric_names, m)?)?;
    m.add_function(wrap_pyfunction!(registry::column_doc, m)?)?;
    m.add_function(wrap_pyfunction!(sim::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(batch::simulate_dicts, m)?)?;
    m.add_function(wrap_pyfunction!(batch::simulate_array, m)?)?;
    m.add_function(wrap_pyfunction!(study::run_study, m)?)?;
    m.add_function(wrap_pyfunction!(sensitivity::sobol_indices, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_hysteresis, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit_friction, m)?)?;
    Ok(())
}
