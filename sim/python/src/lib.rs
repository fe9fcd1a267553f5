//! The `sim` Python package's native half (`sim._sim`): a thin skin over the library's
//! [`sim::Simulation`] facade, so Python scripts drive the same engine as the `sim` command and
//! Rust programs, never a second implementation. The Python half (`python/sim`) adds the
//! Gymnasium and PettingZoo environments on top.
//!
//! The GIL is released while the engine steps; a Python controller takes it back for its call.
//! Readings cross as numpy arrays, copied once (the engine overwrites its buffers each tick).

mod controller;
mod convert;
mod errors;
mod robot;
mod simulation;
mod vector;

use pyo3::prelude::*;

#[pymodule]
fn _sim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    errors::register(m)?;
    m.add_class::<simulation::PySimulation>()?;
    m.add_class::<vector::PyVecSimulation>()?;
    m.add_class::<robot::PyRobot>()?;
    m.add_class::<robot::PyScan>()?;
    m.add_class::<robot::PyEstimate>()?;
    m.add_class::<controller::PyObservation>()?;
    m.add_function(wrap_pyfunction!(simulation::scenarios, m)?)?;
    m.add_function(wrap_pyfunction!(simulation::assets_dir, m)?)?;
    m.add_function(wrap_pyfunction!(simulation::use_bundled_assets, m)?)?;
    Ok(())
}
