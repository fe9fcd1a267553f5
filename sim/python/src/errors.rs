//! The package's exceptions: the engine's own error text, never a crash of the interpreter.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    _sim,
    SimError,
    PyException,
    "The engine refused a request: an unknown robot, place, door or localizer, a value out of \
     range, a simulation that is finished or busy."
);
create_exception!(
    _sim,
    ScenarioError,
    SimError,
    "A scenario that cannot be loaded: its file, line and key, and what was expected."
);

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SimError", py.get_type::<SimError>())?;
    m.add("ScenarioError", py.get_type::<ScenarioError>())?;
    Ok(())
}

/// A refusal of the facade.
pub fn sim_error(e: sim::SimError) -> PyErr {
    SimError::new_err(e.to_string())
}

/// A failure to load or build a scenario, with its whole chain of causes.
pub fn scenario_error(e: anyhow::Error) -> PyErr {
    ScenarioError::new_err(format!("{e:#}"))
}

/// Any other failure of the engine (writing a recording, finishing a run).
pub fn engine_error(e: anyhow::Error) -> PyErr {
    SimError::new_err(format!("{e:#}"))
}
