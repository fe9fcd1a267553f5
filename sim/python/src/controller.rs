//! Python controllers: a callable given a robot's observation each tick, returning its
//! velocity command `(v, w)`.
//!
//! The observation reads the engine's world in place, so it is valid during the call only:
//! the world is borrowed, unchanged, for as long as the call lasts, and the observation is
//! closed (under a write lock no read can straddle) before the engine goes on. A controller
//! that raises ends the run: the engine sees a failed controller (a NaN command stops the
//! robot and the simulation), and the simulation re-raises the exception once the run is
//! finished and its recordings written.

use crate::robot::{PyRobot, Source};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use sim::run::view::Twist;
use sim::{Controller, Observation};
use std::ptr::NonNull;
use std::sync::{Arc, Mutex, RwLock};

/// A controller's observation while its call lasts.
pub struct Scope {
    observation: RwLock<Option<NonNull<Observation<'static>>>>,
}

// SAFETY: the pointer is dereferenced only under the read lock while it is `Some`, which it is
// only during the controller's call, while the engine holds the observation (and the world it
// borrows) immutably; `close` takes the write lock, so no read outlives the call.
unsafe impl Send for Scope {}
unsafe impl Sync for Scope {}

impl Scope {
    fn open(observation: &Observation<'_>) -> Arc<Scope> {
        let ptr = NonNull::from(observation).cast::<Observation<'static>>();
        Arc::new(Scope {
            observation: RwLock::new(Some(ptr)),
        })
    }

    fn close(&self) {
        *self.observation.write().unwrap_or_else(|e| e.into_inner()) = None;
    }

    /// `f` on the observation, or an error once its call is over.
    pub fn with<R>(&self, f: impl FnOnce(&Observation<'_>) -> PyResult<R>) -> PyResult<R> {
        let guard = self.observation.read().unwrap_or_else(|e| e.into_inner());
        match *guard {
            // SAFETY: see the `Send`/`Sync` impls: `Some` only during the call.
            Some(ptr) => f(unsafe { ptr.as_ref() }),
            None => Err(PyRuntimeError::new_err(
                "an observation is valid during its controller's call only; keep the values, \
                 not the observation",
            )),
        }
    }
}

/// The first exception a Python controller raised, for the simulation to re-raise.
pub type Raised = Arc<Mutex<Option<PyErr>>>;

/// A Python callable as a [`Controller`].
pub struct PyController {
    pub callback: Py<PyAny>,
    pub robot: String,
    pub raised: Raised,
}

impl PyController {
    fn call(&self, py: Python<'_>, observation: &Observation<'_>) -> PyResult<Twist> {
        let scope = Scope::open(observation);
        let obs = Py::new(
            py,
            PyObservation {
                time: observation.time,
                dt: observation.dt,
                tick: observation.tick,
                robot: Py::new(
                    py,
                    PyRobot::new(
                        Source::Observation(scope.clone()),
                        self.robot.clone(),
                        observation.robot.index(),
                    ),
                )?,
            },
        )?;
        let result = self.callback.call1(py, (obs,));
        scope.close();
        let value = result?;
        let (v, w): (f64, f64) = value.extract(py).map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "the controller of `{}` returned {}; expected a command (v, w) of two numbers",
                self.robot,
                value
                    .bind(py)
                    .repr()
                    .map_or_else(|_| "?".into(), |r| r.to_string())
            ))
        })?;
        if !(v.is_finite() && w.is_finite()) {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "the controller of `{}` returned ({v}, {w}); expected finite numbers",
                self.robot
            )));
        }
        Ok(Twist { v, w })
    }
}

impl Controller for PyController {
    fn control(&mut self, observation: &Observation) -> Twist {
        Python::attach(|py| match self.call(py, observation) {
            Ok(t) => t,
            Err(e) => {
                let mut raised = self.raised.lock().unwrap_or_else(|e| e.into_inner());
                raised.get_or_insert(e);
                // the engine stops the robot and refuses further ticks
                Twist {
                    v: f64::NAN,
                    w: f64::NAN,
                }
            }
        })
    }
}

/// What a controller sees at a tick; valid during its call only.
#[pyclass(module = "sim._sim", name = "Observation", frozen, get_all)]
pub struct PyObservation {
    /// Simulated time at the start of the tick (s).
    time: f64,
    /// The tick's length (s).
    dt: f64,
    /// The tick's number (0 for the first).
    tick: u64,
    /// The robot: its sensors' latest readings, odometry, estimates and (for evaluation) its
    /// true pose, read as `sim.Robot` reads them.
    robot: Py<PyRobot>,
}

#[pymethods]
impl PyObservation {
    fn __repr__(&self) -> String {
        format!("<sim.Observation tick {} at {:.3} s>", self.tick, self.time)
    }
}
