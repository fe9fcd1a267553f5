//! `sim.Robot`: one robot of a simulation, read between ticks (through the simulation) or
//! during a controller's call (through its observation), and commanded between ticks.

use crate::controller::Scope;
use crate::convert::{PoseTuple, array, point_from, pose, pose_from};
use crate::errors::{SimError, sim_error};
use crate::simulation::PySimulation;
use numpy::{PyArray1, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use sim::Command;
use sim::run::RobotView;
use sim::run::command::Target;
use sim::scenario::SensorName;
use std::sync::Arc;
use systems::navigation::{Goal, Task, TaskKind};

/// Where a robot is read from.
pub enum Source {
    /// A simulation between ticks.
    Simulation(Py<PySimulation>),
    /// A controller's observation, valid during its call.
    Observation(Arc<Scope>),
}

/// One robot of a simulation: its true state, sensors' latest readings, estimators and
/// navigation, read when asked (each read sees the simulation as it is now), and its commands.
#[pyclass(module = "sim._sim", name = "Robot", frozen)]
pub struct PyRobot {
    pub(crate) source: Source,
    name: String,
    index: usize,
}

impl PyRobot {
    pub fn new(source: Source, name: String, index: usize) -> Self {
        PyRobot {
            source,
            name,
            index,
        }
    }

    /// `f` on the robot's view, wherever it is read from.
    fn with_view<R>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&RobotView) -> PyResult<R>,
    ) -> PyResult<R> {
        match &self.source {
            Source::Simulation(s) => s
                .get()
                .with_sim(py, |sim| f(&sim.robot(&self.name).map_err(sim_error)?)),
            Source::Observation(scope) => scope.with(|obs| f(&obs.robot)),
        }
    }

    /// A command for the next tick (between ticks only).
    fn command(&self, py: Python<'_>, command: Command) -> PyResult<()> {
        match &self.source {
            Source::Simulation(s) => s.get().with_sim_mut(py, |sim| {
                sim.command(&self.name, command).map_err(sim_error)
            }),
            Source::Observation(_) => Err(SimError::new_err(format!(
                "`{}`: a controller returns its command; other commands are given between \
                 ticks, on the robot read from the simulation",
                self.name
            ))),
        }
    }
}

fn sensor_name(name: &str) -> PyResult<SensorName> {
    match name {
        "laser" => Ok(SensorName::Laser),
        "encoder" => Ok(SensorName::Encoder),
        "sonar" => Ok(SensorName::Sonar),
        _ => Err(PyValueError::new_err(format!(
            "sensor `{name}`: expected laser, encoder or sonar"
        ))),
    }
}

/// A place name or an `(x, y)` point.
fn target(what: &str, to: &Bound<'_, PyAny>) -> PyResult<Target> {
    if let Ok(name) = to.extract::<String>() {
        return Ok(Target::Place(name));
    }
    let v: Vec<f64> = to
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{what}: expected a place name or (x, y)")))?;
    Ok(Target::Point(point_from(what, &v)?))
}

/// A goal of a task: a place of the scenario or a point.
fn goal(py: Python<'_>, robot: &PyRobot, what: &str, to: &Bound<'_, PyAny>) -> PyResult<Goal> {
    match target(what, to)? {
        Target::Point(p) => Ok(Goal {
            name: format!("({:.2}, {:.2})", p[0], p[1]),
            pose: systems::core::Pose2::new(p[0], p[1], 0.0),
        }),
        Target::Place(name) => {
            let Source::Simulation(s) = &robot.source else {
                return Err(SimError::new_err("tasks are given between ticks"));
            };
            let pose = s.get().with_sim(py, |sim| {
                sim.scenario().places.get(&name).copied().ok_or_else(|| {
                    let known: Vec<&str> =
                        sim.scenario().places.keys().map(String::as_str).collect();
                    SimError::new_err(format!(
                        "{what}: no place named `{name}` (places: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ))
                })
            })?;
            Ok(Goal { name, pose })
        }
    }
}

#[pymethods]
impl PyRobot {
    /// The robot's name in the scenario.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Its place in the scenario's robot list.
    #[getter]
    fn index(&self) -> usize {
        self.index
    }

    /// The true pose `(x, y, theta)` (ground truth, world frame; m, rad).
    #[getter]
    fn pose(&self, py: Python<'_>) -> PyResult<PoseTuple> {
        self.with_view(py, |v| Ok(pose(v.pose())))
    }

    /// The true velocity `(v, w)` (m/s, rad/s).
    #[getter]
    fn twist(&self, py: Python<'_>) -> PyResult<(f64, f64)> {
        self.with_view(py, |v| {
            let t = v.twist();
            Ok((t.v, t.w))
        })
    }

    /// The pose integrated from the wheel encoders, or None without encoders.
    #[getter]
    fn odometry(&self, py: Python<'_>) -> PyResult<Option<PoseTuple>> {
        self.with_view(py, |v| Ok(v.odometry().map(pose)))
    }

    /// The laser's parameters: a dict of `beams`, `fov`, `increment`, `min_range`,
    /// `max_range` (m, rad) and `rate` (Hz); None without a laser.
    #[getter]
    fn laser<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Source::Simulation(s) = &self.source else {
            return Err(SimError::new_err(
                "the laser's parameters are read from the simulation's robot, not an observation",
            ));
        };
        s.get().with_sim(py, |sim| {
            let Some(l) = &sim.scenario().robots[self.index].laser else {
                return Ok(None);
            };
            let d = PyDict::new(py);
            d.set_item("beams", l.beams())?;
            d.set_item("fov", l.fov)?;
            d.set_item("increment", l.increment)?;
            d.set_item("min_range", l.min_range)?;
            d.set_item("max_range", l.max_range)?;
            d.set_item("rate", l.rate)?;
            Ok(Some(d))
        })
    }

    /// The latest laser scan (of this tick or an earlier one), or None.
    #[getter]
    fn scan(&self, py: Python<'_>) -> PyResult<Option<PyScan>> {
        self.with_view(py, |v| {
            Ok(v.scan().map(|s| {
                let scan = s.scan();
                PyScan {
                    stamp: scan.stamp,
                    angle_min: scan.angle_min,
                    angle_increment: scan.angle_increment,
                    range_min: scan.range_min,
                    range_max: scan.range_max,
                    ranges: PyArray1::from_slice(py, &scan.ranges).unbind(),
                    sensor_pose: s.sensor_pose().map(pose),
                }
            }))
        })
    }

    /// The latest scan's ranges as a float32 array (m; inf for no return), or None.
    #[getter]
    fn ranges<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<f32>>>> {
        self.with_view(py, |v| {
            Ok(v.scan().map(|s| PyArray1::from_slice(py, s.ranges())))
        })
    }

    /// The encoder readings of the last tick: an int64 array of `(left_ticks, right_ticks)`
    /// rows (one per reading; none between readings).
    #[getter]
    fn encoder<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.with_view(py, |v| {
            let r = v.encoder_readings();
            let data = r
                .iter()
                .flat_map(|e| [e.left_ticks, e.right_ticks])
                .collect();
            array(py, data, &[r.len(), 2])
        })
    }

    /// The encoder readings of the last tick in full: dicts of `stamp`, `left_ticks`,
    /// `right_ticks` and `steer` (a car's measured steering angle, rad).
    #[getter]
    fn encoder_readings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        self.with_view(py, |v| {
            let list = PyList::empty(py);
            for e in v.encoder_readings() {
                let d = PyDict::new(py);
                d.set_item("stamp", e.stamp)?;
                d.set_item("left_ticks", e.left_ticks)?;
                d.set_item("right_ticks", e.right_ticks)?;
                d.set_item("steer", e.steer)?;
                list.append(d)?;
            }
            Ok(list)
        })
    }

    /// The latest sonar ranges (m, one per mount) as a float32 array, or None.
    #[getter]
    fn sonar<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<f32>>>> {
        self.with_view(py, |v| {
            Ok(v.sonar().map(|s| PyArray1::from_slice(py, &s.latest)))
        })
    }

    /// The GPS fixes of the last tick: dicts of `stamp`, `lat`, `lon` (degrees), `altitude`
    /// (m) and `covariance` (east, north, up variances, m²).
    #[getter]
    fn gps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        self.with_view(py, |v| {
            let list = PyList::empty(py);
            for f in v.gps_fixes() {
                let d = PyDict::new(py);
                d.set_item("stamp", f.stamp)?;
                d.set_item("lat", f.position.lat)?;
                d.set_item("lon", f.position.lon)?;
                d.set_item("altitude", f.altitude)?;
                d.set_item("covariance", f.covariance.to_vec())?;
                list.append(d)?;
            }
            Ok(list)
        })
    }

    /// The compass readings of the last tick: dicts of `stamp`, `azimuth` (rad) and
    /// `variance` (rad²).
    #[getter]
    fn compass<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        self.with_view(py, |v| {
            let list = PyList::empty(py);
            for c in v.compass_readings() {
                let d = PyDict::new(py);
                d.set_item("stamp", c.stamp)?;
                d.set_item("azimuth", c.azimuth)?;
                d.set_item("variance", c.variance)?;
                list.append(d)?;
            }
            Ok(list)
        })
    }

    /// The latest camera frame as an `H × W × 3` uint8 array (RGB), or None.
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.with_view(py, |v| {
            v.camera_image()
                .map(|img| {
                    let shape = [img.height as usize, img.width as usize, 3];
                    array(py, img.rgb, &shape)
                })
                .transpose()
        })
    }

    /// The latest estimate of every localizer and SLAM system, in the scenario's order.
    #[getter]
    fn localizers(&self, py: Python<'_>) -> PyResult<Vec<PyEstimate>> {
        self.with_view(py, |v| {
            v.localizers()
                .iter()
                .map(|l| PyEstimate::new(py, l))
                .collect()
        })
    }

    /// The latest estimate of the localizer or SLAM system called `name`.
    fn localizer(&self, py: Python<'_>, name: &str) -> PyResult<PyEstimate> {
        self.with_view(py, |v| {
            PyEstimate::new(py, &v.localizer(name).map_err(sim_error)?)
        })
    }

    /// SLAM system `name`'s map so far: a dict of `p` (P(occupied) per cell, float32, rows
    /// from the bottom of the map: `p[row, col]`), `resolution` (m) and `origin` (the
    /// lower-left corner, m). None for a localizer.
    fn slam_map<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.with_view(py, |v| {
            let Some(map) = v.localizer(name).map_err(sim_error)?.map() else {
                return Ok(None);
            };
            let d = PyDict::new(py);
            d.set_item("p", array(py, map.p, &[map.height, map.width])?)?;
            d.set_item("resolution", map.resolution)?;
            d.set_item("origin", (map.origin[0], map.origin[1]))?;
            Ok(Some(d))
        })
    }

    /// SLAM system `name`'s best trajectory so far: an `n × 4` array of `(t, x, y, theta)`
    /// rows (empty for a localizer).
    fn trajectory<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        self.with_view(py, |v| {
            let t = v.localizer(name).map_err(sim_error)?.trajectory();
            let n = t.len();
            let data = t
                .into_iter()
                .flat_map(|(s, p)| [s, p.x, p.y, p.theta])
                .collect();
            array(py, data, &[n, 4])
        })
    }

    /// The navigator's state: a dict of `tasks_done`, `tasks`, `finished`, `phase` and
    /// `status`; None for a robot driven by a behaviour.
    #[getter]
    fn navigation<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.with_view(py, |v| {
            let Some(n) = v.navigation() else {
                return Ok(None);
            };
            let d = PyDict::new(py);
            d.set_item("tasks_done", n.tasks_done())?;
            d.set_item("tasks", n.tasks())?;
            d.set_item("finished", n.finished())?;
            d.set_item("phase", format!("{:?}", n.phase()))?;
            d.set_item("status", n.status())?;
            Ok(Some(d))
        })
    }

    /// Collisions so far: a dict of `wall`, `robot`, `person` and `total`.
    #[getter]
    fn collisions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.with_view(py, |v| {
            let c = v.collisions();
            let d = PyDict::new(py);
            d.set_item("wall", c.wall)?;
            d.set_item("robot", c.robot)?;
            d.set_item("person", c.person)?;
            d.set_item("total", c.total())?;
            Ok(d)
        })
    }

    /// Distance driven so far (m).
    #[getter]
    fn distance(&self, py: Python<'_>) -> PyResult<f64> {
        self.with_view(py, |v| Ok(v.distance()))
    }

    /// Holds the velocity command `v` (m/s), `w` (rad/s) from the next tick until replaced or
    /// released; the robot's limits apply.
    fn drive(&self, py: Python<'_>, v: f64, w: f64) -> PyResult<()> {
        self.command(py, Command::Drive { v, w })
    }

    /// A car's command: forward `speed` (m/s) and steering angle `steer` (rad), held.
    fn steer(&self, py: Python<'_>, speed: f64, steer: f64) -> PyResult<()> {
        self.command(py, Command::Steer { speed, steer })
    }

    /// Drops the held command: the behaviour, navigator or controller drives again.
    fn release(&self, py: Python<'_>) -> PyResult<()> {
        self.command(py, Command::Release)
    }

    /// Carries the robot to `pose` (`(x, y)` or `(x, y, theta)`) without telling its
    /// estimators: a kidnapping.
    fn teleport(&self, py: Python<'_>, pose: Vec<f64>) -> PyResult<()> {
        let p = pose_from("teleport pose", &pose)?;
        self.command(py, Command::Teleport(p))
    }

    /// A new route of `(x, y)` points for a robot driven by a behaviour.
    #[pyo3(signature = (points, looping = false))]
    fn waypoints(&self, py: Python<'_>, points: Vec<Vec<f64>>, looping: bool) -> PyResult<()> {
        let points = points
            .iter()
            .enumerate()
            .map(|(i, p)| point_from(&format!("waypoint {i}"), p))
            .collect::<PyResult<Vec<_>>>()?;
        self.command(py, Command::Waypoints { points, looping })
    }

    /// Sends a navigating robot to a place (its name) or a point `(x, y)`, after its tasks.
    fn go_to(&self, py: Python<'_>, to: &Bound<'_, PyAny>) -> PyResult<()> {
        let t = target("go_to", to)?;
        self.command(py, Command::GoTo(t))
    }

    /// Appends a delivery to a navigating robot's tasks: drive to `pickup`, load for `load`
    /// s, drive to `dropoff`, unload for `unload` s (places or points).
    #[pyo3(signature = (pickup, dropoff, load = 20.0, unload = 30.0, name = None))]
    fn deliver(
        &self,
        py: Python<'_>,
        pickup: &Bound<'_, PyAny>,
        dropoff: &Bound<'_, PyAny>,
        load: f64,
        unload: f64,
        name: Option<String>,
    ) -> PyResult<()> {
        let from = goal(py, self, "deliver pickup", pickup)?;
        let to = goal(py, self, "deliver dropoff", dropoff)?;
        let name = name.unwrap_or_else(|| format!("delivery_{}_{}", from.name, to.name));
        let kind = TaskKind::Delivery {
            from,
            to,
            load,
            unload,
        };
        self.command(py, Command::Tasks(vec![Task { name, kind }]))
    }

    /// Appends a wait of `seconds` where the robot is to a navigating robot's tasks.
    #[pyo3(signature = (seconds, name = None))]
    fn wait(&self, py: Python<'_>, seconds: f64, name: Option<String>) -> PyResult<()> {
        let name = name.unwrap_or_else(|| format!("wait_{seconds}"));
        let kind = TaskKind::Wait { time: seconds };
        self.command(py, Command::Tasks(vec![Task { name, kind }]))
    }

    /// Silences one of the robot's sensors (`laser`, `encoder`, `sonar`) or, with
    /// `active=False`, ends the fault.
    #[pyo3(signature = (sensor, active = true))]
    fn sensor_fault(&self, py: Python<'_>, sensor: &str, active: bool) -> PyResult<()> {
        let sensor = sensor_name(sensor)?;
        self.command(py, Command::SensorFault { sensor, active })
    }

    fn __repr__(&self) -> String {
        format!("<sim.Robot {:?} #{}>", self.name, self.index)
    }
}

/// A laser scan as the sensor reported it.
#[pyclass(module = "sim._sim", name = "Scan", frozen, get_all)]
pub struct PyScan {
    /// When it was taken (s).
    stamp: f64,
    /// The first beam's angle in the sensor frame (rad).
    angle_min: f32,
    /// The angle between beams (rad).
    angle_increment: f32,
    /// Shorter returns are invalid (m).
    range_min: f32,
    /// Longer returns are none (m).
    range_max: f32,
    /// The ranges (float32, m; inf for no return).
    ranges: Py<PyArray1<f32>>,
    /// The true sensor pose it was taken from `(x, y, theta)`, when known.
    sensor_pose: Option<PoseTuple>,
}

#[pymethods]
impl PyScan {
    /// The beam angles in the sensor frame (float32, rad), one per range.
    #[getter]
    fn angles<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let n = self.ranges.bind(py).len();
        let a: Vec<f32> = (0..n)
            .map(|i| self.angle_min + i as f32 * self.angle_increment)
            .collect();
        Ok(PyArray1::from_vec(py, a))
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        Ok(format!(
            "<sim.Scan at {:.3} s, {} beams>",
            self.stamp,
            self.ranges.bind(py).len()
        ))
    }
}

/// A localizer's or SLAM system's latest estimate.
#[pyclass(module = "sim._sim", name = "Estimate", frozen, get_all)]
pub struct PyEstimate {
    /// The name given in the scenario.
    name: String,
    /// Its type as scenario files write it (`mcl`, `markov_grid`, ...).
    kind: String,
    /// The time of the data it comes from (s); None before the first estimate.
    stamp: Option<f64>,
    /// The estimated pose `(x, y, theta)` (map frame); None before the first estimate.
    pose: Option<PoseTuple>,
    /// Its 3 × 3 covariance over (x, y, theta) (m², rad²); None before the first estimate.
    covariance: Option<Py<PyAny>>,
    /// When its estimates came and stayed close to the truth (s), None if not (yet).
    converged_after: Option<f64>,
    /// True while the robot's laser is faulted or its scans have no usable beam: the estimate
    /// is the last one carried forward by the odometry, its covariance growing with the path.
    degraded: bool,
}

impl PyEstimate {
    fn new(py: Python<'_>, l: &sim::run::view::LocalizerView) -> PyResult<Self> {
        let covariance = l
            .estimate
            .map(|e| array(py, e.covariance.concat(), &[3, 3]).map(Bound::unbind))
            .transpose()?;
        Ok(PyEstimate {
            name: l.name.to_string(),
            kind: l.kind.to_string(),
            stamp: l.estimate.map(|e| e.stamp),
            pose: l.estimate.map(|e| pose(e.pose)),
            covariance,
            converged_after: l.converged_after,
            degraded: l.degraded,
        })
    }
}

#[pymethods]
impl PyEstimate {
    fn __repr__(&self) -> String {
        match self.pose {
            Some((x, y, t)) => format!(
                "<sim.Estimate {} ({}): ({x:.3}, {y:.3}, {t:.3}){}>",
                self.name,
                self.kind,
                if self.degraded { ", degraded" } else { "" }
            ),
            None => format!("<sim.Estimate {} ({}): none yet>", self.name, self.kind),
        }
    }
}
