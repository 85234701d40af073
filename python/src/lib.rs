//! `jointrom._native`, the extension module under the Python package `jointrom`
//! (`python/jointrom/`): the library the CLI uses, reached from Python with numpy arrays in and
//! out. No numerics of its own: every number comes from the `jointrom` crate.
//!
//! - `model`: `load` → `Model` (info, modes, statics, K and M, the full transient, `reduce`);
//! - `rom`: `Rom` (Φ and the reduced matrices, its transient, the file and the FMU), `load_rom`;
//! - `run`: `RunResult` and the transient options from keyword arguments;
//! - `worker`: long work off the GIL on a worker thread, with Ctrl-C and a progress callback;
//! - `errors`: the `jointrom.Error` hierarchy; `convert`: arrays, JSON values and dicts.

use pyo3::prelude::*;

mod convert;
mod errors;
mod model;
mod rom;
mod run;
mod worker;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // As the CLI's main: one thread per factorization, so results are bit-identical to it.
    faer::set_global_parallelism(faer::Par::Seq);
    errors::register(m)?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<rom::Rom>()?;
    m.add_class::<run::RunResult>()?;
    m.add_function(wrap_pyfunction!(model::load, m)?)?;
    m.add_function(wrap_pyfunction!(rom::load_rom, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
