//! `sim.Simulation`: one scenario's world, stepped from Python.

use crate::controller::{PyController, Raised};
use crate::convert::{array, pose};
use crate::errors::{SimError, engine_error, scenario_error, sim_error};
use crate::robot::{PyRobot, Source};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use sim::formats::tum::RobotLocalization;
use sim::{Finished, Simulation, SimulationBuilder};
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard, TryLockError};

enum State {
    Running(Box<Simulation>),
    /// The run was finished: its summary (JSON), estimates and event log.
    Finished {
        summary: String,
        localization: Vec<RobotLocalization>,
        log: Vec<(f64, String, String)>,
    },
}

/// A running simulation of one scenario: step it, read its robots, command them, and finish
/// it for its summary. Built by `Simulation(...)`, `Simulation.load(...)` or
/// `Simulation.from_toml(...)`.
#[pyclass(module = "sim._sim", name = "Simulation", frozen)]
pub struct PySimulation {
    state: Mutex<State>,
    /// The first exception a Python controller raised.
    raised: Raised,
    robots: Vec<String>,
    name: String,
    dt: f64,
}

/// The builder's options every constructor takes.
pub struct Options<'py> {
    seed: Option<u64>,
    duration: Option<f64>,
    threads: usize,
    set: Option<Bound<'py, PyDict>>,
    rrd: Option<PathBuf>,
    mcap: Option<PathBuf>,
    carmen: Option<PathBuf>,
    save_map: Option<PathBuf>,
    controllers: Option<Bound<'py, PyDict>>,
    cache: bool,
}

/// A `set` value as the command line's `--set KEY=VALUE` writes it.
fn set_text(key: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(b) = v.extract::<bool>() {
        return Ok(b.to_string());
    }
    if let Ok(s) = v.extract::<String>() {
        return Ok(s);
    }
    if v.extract::<f64>().is_ok() {
        return Ok(v.str()?.to_string());
    }
    Err(PyValueError::new_err(format!(
        "set {key}: expected a string, number or bool (TOML value text), got {}",
        v.get_type().name()?
    )))
}

const OPTIONS: &str =
    "seed, duration, threads, set, rrd, mcap, carmen, save_map, controllers, cache";

impl<'py> Options<'py> {
    /// The keyword options of a constructor, each checked for its type.
    pub fn from_kwargs(kwargs: Option<&Bound<'py, PyDict>>) -> PyResult<Self> {
        let mut o = Options {
            seed: None,
            duration: None,
            threads: 0,
            set: None,
            rrd: None,
            mcap: None,
            carmen: None,
            save_map: None,
            controllers: None,
            cache: true,
        };
        let Some(kwargs) = kwargs else {
            return Ok(o);
        };
        for (k, v) in kwargs.iter() {
            let key: String = k.extract()?;
            let got = v
                .get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string());
            let bad = |expected: &str| {
                pyo3::exceptions::PyTypeError::new_err(format!(
                    "option `{key}`: expected {expected}, got {got}"
                ))
            };
            if v.is_none() {
                continue;
            }
            match key.as_str() {
                "seed" => o.seed = Some(v.extract().map_err(|_| bad("an int >= 0"))?),
                "duration" => o.duration = Some(v.extract().map_err(|_| bad("seconds"))?),
                "threads" => o.threads = v.extract().map_err(|_| bad("an int >= 0"))?,
                "set" => o.set = Some(v.clone().cast_into::<PyDict>().map_err(|_| bad("a dict"))?),
                "rrd" => o.rrd = Some(v.extract().map_err(|_| bad("a path"))?),
                "mcap" => o.mcap = Some(v.extract().map_err(|_| bad("a path"))?),
                "carmen" => o.carmen = Some(v.extract().map_err(|_| bad("a path"))?),
                "save_map" => o.save_map = Some(v.extract().map_err(|_| bad("a path"))?),
                "controllers" => {
                    o.controllers =
                        Some(v.clone().cast_into::<PyDict>().map_err(|_| bad("a dict"))?)
                }
                "cache" => o.cache = v.extract().map_err(|_| bad("a bool"))?,
                _ => {
                    return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                        "unknown option `{key}` (options: {OPTIONS})"
                    )));
                }
            }
        }
        Ok(o)
    }

    /// The options that shape the world (seed, duration, threads, overrides, cache).
    pub fn apply_plain(&self, mut b: SimulationBuilder) -> PyResult<SimulationBuilder> {
        if let Some(s) = self.seed {
            b = b.seed(s);
        }
        if let Some(d) = self.duration {
            b = b.duration(d);
        }
        if self.threads > systems::core::pool::MAX_THREADS {
            return Err(PyValueError::new_err(format!(
                "threads: expected 0 (one per core) or 1 to {}, got {}",
                systems::core::pool::MAX_THREADS,
                self.threads
            )));
        }
        b = b.threads(self.threads);
        if let Some(set) = &self.set {
            for (k, v) in set.iter() {
                let key: String = k.extract().map_err(|_| {
                    PyValueError::new_err("set: expected string keys (`robots[0].seed`)")
                })?;
                let text = set_text(&key, &v)?;
                b = b.set(&key, &text);
            }
        }
        Ok(b.cache(self.map_cache()))
    }

    /// The on-disk cache of map structures, or none with `cache=False`.
    pub fn map_cache(&self) -> systems::core::cache::MapCache {
        if self.cache {
            sim::cache::from_env(false)
        } else {
            systems::core::cache::MapCache::disabled()
        }
    }

    /// Every option: the world's, the outputs and the controllers.
    fn apply(self, b: SimulationBuilder, raised: &Raised) -> PyResult<SimulationBuilder> {
        let mut b = self.apply_plain(b)?;
        if let Some(p) = self.rrd {
            b = b.rrd(p);
        }
        if let Some(p) = self.mcap {
            b = b.mcap(p);
        }
        if let Some(p) = self.carmen {
            b = b.carmen(p);
        }
        if let Some(p) = self.save_map {
            b = b.save_map(p);
        }
        if let Some(ctrls) = self.controllers {
            for (k, v) in ctrls.iter() {
                let robot: String = k.extract().map_err(|_| {
                    PyValueError::new_err("controllers: expected robot names as keys")
                })?;
                if !v.is_callable() {
                    return Err(PyValueError::new_err(format!(
                        "controllers[{robot:?}]: expected a callable taking an observation \
                         and returning (v, w)"
                    )));
                }
                let c = PyController {
                    callback: v.unbind(),
                    robot: robot.clone(),
                    raised: raised.clone(),
                };
                b = b.controller(&robot, c);
            }
        }
        Ok(b)
    }
}

impl PySimulation {
    fn build(py: Python<'_>, builder: SimulationBuilder, opts: Options<'_>) -> PyResult<Self> {
        let raised = Raised::default();
        let builder = opts.apply(builder, &raised)?;
        let sim = py.detach(move || builder.build()).map_err(scenario_error)?;
        let sc = sim.scenario();
        Ok(PySimulation {
            robots: sc.robots.iter().map(|r| r.name.clone()).collect(),
            name: sc.name.clone(),
            dt: sc.dt,
            raised,
            state: Mutex::new(State::Running(Box::new(sim))),
        })
    }

    /// The state, or an error when another call (a controller's, another thread's) holds it.
    fn lock(&self) -> PyResult<MutexGuard<'_, State>> {
        match self.state.try_lock() {
            Ok(g) => Ok(g),
            Err(TryLockError::Poisoned(e)) => Ok(e.into_inner()),
            Err(TryLockError::WouldBlock) => Err(SimError::new_err(format!(
                "simulation `{}` is busy: it is stepping (a controller reads its own robot \
                 through its observation) or another thread uses it",
                self.name
            ))),
        }
    }

    fn finished_error(&self) -> PyErr {
        SimError::new_err(format!(
            "simulation `{}` is finished; build a new one (or reset before finishing)",
            self.name
        ))
    }

    /// `f` on the running simulation.
    pub fn with_sim<R>(
        &self,
        _py: Python<'_>,
        f: impl FnOnce(&Simulation) -> PyResult<R>,
    ) -> PyResult<R> {
        match &*self.lock()? {
            State::Running(sim) => f(sim),
            State::Finished { .. } => Err(self.finished_error()),
        }
    }

    /// `f` on the running simulation, mutably.
    pub fn with_sim_mut<R>(
        &self,
        _py: Python<'_>,
        f: impl FnOnce(&mut Simulation) -> PyResult<R>,
    ) -> PyResult<R> {
        match &mut *self.lock()? {
            State::Running(sim) => f(sim),
            State::Finished { .. } => Err(self.finished_error()),
        }
    }

    /// Steps with the GIL released. A controller's exception finishes the run (its
    /// recordings written) and is re-raised.
    fn advance<R: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut Simulation) -> Result<R, sim::SimError> + Send,
    ) -> PyResult<R> {
        let mut guard = self.lock()?;
        let State::Running(sim) = &mut *guard else {
            return Err(self.finished_error());
        };
        let sim: &mut Simulation = sim;
        match py.detach(move || f(sim)) {
            Ok(r) => Ok(r),
            Err(e) => {
                let raised = self.raised.lock().unwrap_or_else(|e| e.into_inner()).take();
                match raised {
                    Some(err) => {
                        let finished = Self::finish_locked(py, &mut guard);
                        drop(guard);
                        if let Err(f) = finished {
                            // Python 3.11 on: the note prints with the traceback
                            let value = err.value(py);
                            if value.hasattr("add_note")? {
                                value.call_method1(
                                    "add_note",
                                    (format!("finishing the run failed too: {f}"),),
                                )?;
                            }
                        }
                        Err(err)
                    }
                    None => Err(sim_error(e)),
                }
            }
        }
    }

    /// Finishes the run in `state` (GIL released while the files are written).
    fn finish_locked(py: Python<'_>, state: &mut State) -> PyResult<()> {
        let placeholder = State::Finished {
            summary: "null".into(),
            localization: Vec::new(),
            log: Vec::new(),
        };
        let State::Running(sim) = std::mem::replace(state, placeholder) else {
            return Ok(());
        };
        let Finished {
            summary,
            localization,
            log,
            ..
        } = py.detach(move || sim.finish()).map_err(engine_error)?;
        let summary = serde_json::to_string(&summary)
            .map_err(|e| SimError::new_err(format!("summary: {e}")))?;
        *state = State::Finished {
            summary,
            localization,
            log,
        };
        Ok(())
    }

    fn summary_dict<'py>(py: Python<'py>, json: &str) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (json,))
    }
}

#[pymethods]
impl PySimulation {
    /// A bundled scenario by name (`"hospital_patrol"`) or a scenario file, built and ready
    /// for its first tick. Keyword options: `seed`, `duration`, `threads` (0: one per core),
    /// `set` (overrides as `sim run --set KEY=VALUE`: `{"robots[0].seed": 3}`), `rrd`, `mcap`,
    /// `carmen` and `save_map` (what `sim run` writes), `controllers` (`{robot: callable}`),
    /// `cache` (False: build the map's structures without the on-disk cache).
    #[new]
    #[pyo3(signature = (scenario = "hospital_patrol", **options))]
    fn new(py: Python<'_>, scenario: &str, options: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Self::build(
            py,
            Simulation::load(scenario),
            Options::from_kwargs(options)?,
        )
    }

    /// The same as `Simulation(scenario, ...)`.
    #[staticmethod]
    #[pyo3(signature = (scenario, **options))]
    fn load(py: Python<'_>, scenario: &str, options: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Self::new(py, scenario, options)
    }

    /// Scenario TOML text, called `label` in error messages; its relative paths (maps,
    /// places) start from `relative_to` (default: the current folder). Takes the options of
    /// `Simulation(...)`.
    #[staticmethod]
    #[pyo3(signature = (text, *, label = "<string>", relative_to = None, **options))]
    fn from_toml(
        py: Python<'_>,
        text: &str,
        label: &str,
        relative_to: Option<PathBuf>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let mut b = Simulation::from_toml(text, label);
        if let Some(dir) = relative_to {
            b = b.relative_to(dir);
        }
        Self::build(py, b, Options::from_kwargs(options)?)
    }

    /// A scenario built in code: nested dicts and lists with the scenario file's structure
    /// (`{"name": "corridor", "duration": 60.0, "robots": [{"name": "r1", ...}]}`), checked
    /// as a file is, so errors name the key. Relative paths start from `relative_to`. Takes
    /// the options of `Simulation(...)`.
    #[staticmethod]
    #[pyo3(signature = (scenario, *, relative_to = None, **options))]
    fn from_dict(
        py: Python<'_>,
        scenario: &Bound<'_, PyDict>,
        relative_to: Option<PathBuf>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let json: String = py
            .import("json")?
            .call_method1("dumps", (scenario,))?
            .extract()?;
        let table: toml::Table = serde_json::from_str(&json).map_err(|e| {
            PyValueError::new_err(format!(
                "scenario: expected strings, numbers, bools, lists and dicts (TOML has no \
                 None): {e}"
            ))
        })?;
        let text = toml::to_string(&table)
            .map_err(|e| PyValueError::new_err(format!("scenario: not a TOML document: {e}")))?;
        let mut b = Simulation::from_toml(&text, "<dict>");
        if let Some(dir) = relative_to {
            b = b.relative_to(dir);
        }
        Self::build(py, b, Options::from_kwargs(options)?)
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// The tick's length (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    /// The scenario's seed.
    #[getter]
    fn seed(&self, py: Python<'_>) -> PyResult<u64> {
        self.with_sim(py, |s| Ok(s.scenario().seed))
    }

    /// Simulated time (s): the start of the next tick.
    #[getter]
    fn time(&self, py: Python<'_>) -> PyResult<f64> {
        self.with_sim(py, |s| Ok(s.time()))
    }

    /// Ticks run so far.
    #[getter]
    fn ticks(&self, py: Python<'_>) -> PyResult<u64> {
        self.with_sim(py, |s| Ok(s.ticks()))
    }

    /// The ticks of the scenario's duration.
    #[getter]
    fn end_tick(&self, py: Python<'_>) -> PyResult<u64> {
        self.with_sim(py, |s| Ok(s.end_tick()))
    }

    /// The scenario's duration is over, or it ends when its tasks are done and they are.
    #[getter]
    fn is_over(&self, py: Python<'_>) -> PyResult<bool> {
        self.with_sim_mut(py, |s| Ok(s.is_over()))
    }

    /// Whether the run has been finished.
    #[getter]
    fn finished(&self) -> PyResult<bool> {
        Ok(matches!(&*self.lock()?, State::Finished { .. }))
    }

    /// The robots' names, in the scenario's order.
    #[getter]
    fn robot_names(&self) -> Vec<String> {
        self.robots.clone()
    }

    /// One tick of the schedule (the GIL released).
    fn step(&self, py: Python<'_>) -> PyResult<()> {
        self.advance(py, |s| s.step())
    }

    /// Steps `seconds` of simulated time (whole ticks), even past the scenario's duration.
    fn run_for(&self, py: Python<'_>, seconds: f64) -> PyResult<()> {
        self.advance(py, |s| s.run_for(seconds))
    }

    /// Steps until `done(simulation)` is true (checked before every tick) or `max_s`
    /// seconds have passed; whether `done` held.
    fn run_until(slf: &Bound<'_, Self>, done: &Bound<'_, PyAny>, max_s: f64) -> PyResult<bool> {
        let py = slf.py();
        let this = slf.get();
        if !(max_s.is_finite() && max_s >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "max_s: expected a finite number of seconds >= 0, got {max_s}"
            )));
        }
        let ticks = (max_s / this.dt).round() as u64;
        for _ in 0..ticks {
            if done.call1((slf,))?.is_truthy()? {
                return Ok(true);
            }
            this.advance(py, |s| s.step())?;
        }
        done.call1((slf,))?.is_truthy()
    }

    /// Steps to the scenario's end and finishes the run; its summary.
    fn run<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.advance(py, |s| {
            while !s.is_over() {
                s.step()?;
            }
            Ok(())
        })?;
        self.finish(py)
    }

    /// Ends the run where it is: estimators and recordings finished, files written. Returns
    /// the summary (what `sim run --summary` writes) as a dict.
    fn finish<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut guard = self.lock()?;
        Self::finish_locked(py, &mut guard)?;
        match &*guard {
            State::Finished { summary, .. } => Self::summary_dict(py, summary),
            State::Running(_) => unreachable!("finish_locked leaves the run finished"),
        }
    }

    /// The summary of a finished run (a dict), None while it runs.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &*self.lock()? {
            State::Finished { summary, .. } => Self::summary_dict(py, summary).map(Some),
            State::Running(_) => Ok(None),
        }
    }

    /// The finished run's scenario and navigation events: `(time, robot or "", text)`.
    #[getter]
    fn log(&self) -> PyResult<Vec<(f64, String, String)>> {
        match &*self.lock()? {
            State::Finished { log, .. } => Ok(log.clone()),
            State::Running(_) => Err(SimError::new_err("the event log is read once finished")),
        }
    }

    /// The finished run's estimates beside the truth: `{robot: {localizer: array}}`, each an
    /// `n × 7` float64 array of `(t, x, y, theta, true_x, true_y, true_theta)` rows.
    fn trajectories<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let guard = self.lock()?;
        let State::Finished { localization, .. } = &*guard else {
            return Err(SimError::new_err("trajectories are read once finished"));
        };
        let out = PyDict::new(py);
        for r in localization {
            let per = PyDict::new(py);
            for (name, samples) in &r.localizers {
                let data = samples
                    .iter()
                    .flat_map(|s| {
                        let (e, t) = (s.estimate, s.truth);
                        [s.t, e.x, e.y, e.theta, t.x, t.y, t.theta]
                    })
                    .collect();
                per.set_item(name, array(py, data, &[samples.len(), 7])?)?;
            }
            out.set_item(&r.robot, per)?;
        }
        Ok(out)
    }

    /// Writes the finished run's trajectories as TUM files (`DIR/<robot>/<localizer>.tum`
    /// and `.truth.tum`, as `sim run --trajectories` does): from convergence on, or with
    /// `all_estimates` every estimate from the first; the files written.
    #[pyo3(signature = (dir, *, all_estimates = false))]
    fn write_tum(&self, dir: PathBuf, all_estimates: bool) -> PyResult<Vec<PathBuf>> {
        use sim::formats::tum::{Estimates, write_trajectories};
        let guard = self.lock()?;
        let State::Finished { localization, .. } = &*guard else {
            return Err(SimError::new_err("trajectories are written once finished"));
        };
        let which = if all_estimates {
            Estimates::All
        } else {
            Estimates::FromConvergence
        };
        write_trajectories(&dir, localization, which).map_err(engine_error)
    }

    /// Starts the scenario again from its first tick with `seed`, as a simulation built
    /// afresh with that seed (controllers kept with their state). Not for a simulation that
    /// writes recordings.
    fn reset(&self, py: Python<'_>, seed: u64) -> PyResult<()> {
        self.with_sim_mut(py, |s| py.detach(|| s.reset(seed)).map_err(engine_error))
    }

    /// The robot called `name`.
    fn robot(slf: &Bound<'_, Self>, name: &str) -> PyResult<PyRobot> {
        let this = slf.get();
        match this.robots.iter().position(|r| r == name) {
            Some(i) => Ok(PyRobot::new(
                Source::Simulation(slf.clone().unbind()),
                name.to_string(),
                i,
            )),
            None => Err(SimError::new_err(format!(
                "no robot named `{name}` (robots: {})",
                if this.robots.is_empty() {
                    "none".to_string()
                } else {
                    this.robots.join(", ")
                }
            ))),
        }
    }

    /// Every robot, in the scenario's order.
    #[getter]
    fn robots(slf: &Bound<'_, Self>) -> Vec<PyRobot> {
        slf.get()
            .robots
            .iter()
            .enumerate()
            .map(|(i, n)| PyRobot::new(Source::Simulation(slf.clone().unbind()), n.clone(), i))
            .collect()
    }

    /// The walking people: dicts of `name`, `pose` and `next_point`.
    #[getter]
    fn people<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        self.with_sim(py, |s| {
            let list = PyList::empty(py);
            for p in s.people() {
                let d = PyDict::new(py);
                d.set_item("name", p.name)?;
                d.set_item("pose", pose(p.pose))?;
                d.set_item("next_point", p.next_point)?;
                list.append(d)?;
            }
            Ok(list)
        })
    }

    /// The doors: `{name: open}`.
    #[getter]
    fn doors<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.with_sim(py, |s| {
            let d = PyDict::new(py);
            for door in s.doors() {
                d.set_item(door.name, door.open)?;
            }
            Ok(d)
        })
    }

    /// Opens or closes the door called `name` at the next tick.
    fn set_door(&self, py: Python<'_>, name: &str, open: bool) -> PyResult<()> {
        self.with_sim_mut(py, |s| s.set_door(name, open).map_err(sim_error))
    }

    /// The places of the scenario's map: `{name: (x, y, theta)}`.
    #[getter]
    fn places<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.with_sim(py, |s| {
            let d = PyDict::new(py);
            for (name, p) in &s.scenario().places {
                d.set_item(name, pose(*p))?;
            }
            Ok(d)
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "<sim.Simulation {:?}, {} robots>",
            self.name,
            self.robots.len()
        )
    }
}

/// The bundled scenarios' names.
#[pyfunction]
pub fn scenarios() -> PyResult<Vec<String>> {
    let all = sim::scenario::load::bundled_scenarios().map_err(engine_error)?;
    Ok(all.into_iter().map(|(n, _)| n).collect())
}

/// The folder the bundled scenarios, maps and roads are read from: `$SIM_ASSETS` when set,
/// else the copy inside this package, else the repository the package was built from.
#[pyfunction]
pub fn assets_dir() -> std::path::PathBuf {
    sim::scenario::load::assets_dir()
}

/// Called once by the package's `__init__`: its own copy of the assets.
#[pyfunction]
pub fn use_bundled_assets(dir: std::path::PathBuf) {
    sim::scenario::load::use_bundled_assets(dir)
}
