//! glassdb for Python (`import glassdb`): the extension module `glassdb._glassdb`, which the
//! pure-Python package `glassdb` re-exports (python/glassdb/). Every function calls the library
//! entry points the command line calls (the registry's build and tables, the compositor's
//! `compose_in_memory` over the same kernel as `compose`, glassdb-pass's and glassdb-mask's
//! readers, and the commands' own report functions for `stack` and `spectral`), with the GIL
//! released while they run. Errors become the exception class of their `glassdb_io::ErrorKind`
//! (python/glassdb/_errors.py) carrying the message the command would print.

mod commands;
mod errors;
mod frames;
mod registry;

use pyo3::prelude::*;

/// The extension module: the registry, the compositor, passes and masks, the stack engine and
/// spectral data.
#[pymodule]
fn _glassdb(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<registry::PyRegistry>()?;
    m.add_class::<frames::PyPass>()?;
    m.add_function(wrap_pyfunction!(frames::compose, m)?)?;
    m.add_function(wrap_pyfunction!(frames::read_passes, m)?)?;
    m.add_function(wrap_pyfunction!(frames::cryptomatte_mask, m)?)?;
    m.add_function(wrap_pyfunction!(commands::stack, m)?)?;
    m.add_function(wrap_pyfunction!(commands::spectral, m)?)?;
    Ok(())
}
