//! # deadreckon (Python bindings)
//!
//! The native module `deadreckon._native` behind the Python package
//! `deadreckon` (`python/deadreckon/`): drives, calibration, tracks,
//! evaluation, TedriS and the step filter of the Rust crates, with arrays
//! crossing as numpy arrays. The package's Python layer turns column
//! dictionaries into pandas DataFrames and documents the API (`.pyi` stubs).
//!
//! Every error becomes a `deadreckon.DeadreckonError` whose text is the
//! command line's `error:` line (context, then the reader's file/line
//! message); nothing panics across the boundary (pyo3 turns a panic into
//! `PanicException`, which the tests would catch as a failure).
#![deny(missing_docs)]

use pyo3::prelude::*;

mod calib;
mod columns;
mod drive;
mod filter;
mod online;
mod pyjson;
mod tedris;

pyo3::create_exception!(
    _native,
    DeadreckonError,
    pyo3::exceptions::PyException,
    "An error of deadreckon: the message names the file, line and column like the command line's."
);

/// Any error as a `DeadreckonError` with its whole source chain, as the CLI prints it.
pub(crate) fn to_py_err(e: impl std::error::Error + 'static) -> PyErr {
    DeadreckonError::new_err(deadreckon_api::chain_text(&e))
}

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("DeadreckonError", m.py().get_type::<DeadreckonError>())?;
    m.add_class::<drive::Drive>()?;
    m.add_class::<filter::Filter>()?;
    m.add_class::<filter::Update>()?;
    m.add_class::<online::Online>()?;
    m.add_function(wrap_pyfunction!(drive::read_drive, m)?)?;
    m.add_function(wrap_pyfunction!(calib::calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(calib::run_tracks, m)?)?;
    m.add_function(wrap_pyfunction!(calib::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(tedris::tedris_train, m)?)?;
    m.add_function(wrap_pyfunction!(tedris::tedris_run, m)?)?;
    m.add(
        "EVO_DEFAULT_MAX_DIFF_S",
        deadreckon_core::evo::DEFAULT_MAX_DIFF_S,
    )?;
    Ok(())
}
