//! `restpose._native`: the Python extension module of restpose (pyo3), a thin layer over the
//! library: arguments are converted, the library is called (with the GIL released during
//! solves and verifications), its results are handed back as numpy arrays and plain Python
//! objects. The Python package `restpose` (`python/restpose/`) re-exports it with records,
//! exceptions and `restpose.testing`.
//!
//! ```text
//! load / load_string / ModelBuilder --> Model --solve--> Result --to_json--> the CLI's JSON
//!                                           \--verify--> Verification
//! ```
//!
//! Nothing here is global: each `Model` owns its library model (shared read-only with the
//! results made from it).

mod builder;
mod cli;
mod convert;
mod errors;
mod model;
mod options;
mod result;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // A build for extensions this CPU lacks refuses to import (`restpose::cpu`).
    let missing = restpose::cpu::unsupported();
    if !missing.is_empty() {
        return Err(pyo3::exceptions::PyImportError::new_err(format!(
            "this CPU lacks {}: {}",
            missing.join(", "),
            restpose::cpu::REMEDY
        )));
    }
    m.add_class::<model::Model>()?;
    m.add_class::<result::Result>()?;
    m.add_class::<builder::ModelBuilder>()?;
    m.add_function(wrap_pyfunction!(model::load, m)?)?;
    m.add_function(wrap_pyfunction!(model::load_string, m)?)?;
    m.add_function(wrap_pyfunction!(cli::run_cli, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
