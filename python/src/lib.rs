//! The extension module `hbal._hbal`: a thin layer over the hbal library for the Python
//! package `hbal` (python/hbal). Scenes are built from Python documents ([`value`],
//! [`scene`]), analyses run with the GIL released and return their serde records
//! ([`analyses`]), force laws may be Python functions ([`law`]), errors are Python
//! exceptions by the exit-code contract ([`errors`]), sweeps report progress and stop on
//! Ctrl-C ([`progress`]).

mod analyses;
mod document;
mod errors;
mod law;
mod options;
mod out;
mod progress;
mod record;
mod report;
mod scene;
mod thread_state;
mod value;

use pyo3::prelude::*;

#[pymodule]
fn _hbal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<scene::SceneHandle>()?;
    m.add_class::<record::Record>()?;
    m.add_function(wrap_pyfunction!(scene::build_scene, m)?)?;
    m.add_function(wrap_pyfunction!(document::parse_scene, m)?)?;
    m.add_function(wrap_pyfunction!(document::read_scene, m)?)?;
    m.add_function(wrap_pyfunction!(document::document_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(document::set_parameter, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::solve, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::parameter_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::modes, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::compare, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::check, m)?)?;
    m.add_function(wrap_pyfunction!(report::report, m)?)?;
    m.add_function(wrap_pyfunction!(analyses::limit_threads_here, m)?)?;
    m.add("SCHEMA_VERSION", hbal::analysis::SCHEMA_VERSION)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
