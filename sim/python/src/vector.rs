//! `sim.VecSimulation`: N independent worlds of one scenario stepped together, for learning
//! and batch experiments. One call takes every robot's velocity command as an `(N, R, 2)`
//! array, steps every world on the engine's thread pool with the GIL released, and returns
//! stacked observations. A world whose episode has ended starts its next one at the following
//! call (Gymnasium 1.x's `NEXT_STEP` autoreset), through [`Simulation::reset`].
//!
//! Episode k of world i runs with seed `seed + i + k·N` (modulo 2⁶⁴): the first episodes are seeds
//! `seed … seed + N − 1`, and no two episodes share a seed. Each world runs its kernels on the
//! thread that steps it, so world i with seed s follows the trajectory of a single
//! `Simulation` with seed s, whatever N and the thread count. That thread is the same at every
//! call (`KernelPool::for_each_pinned`), so a world's state stays in its core's caches.

use crate::convert::array;
use crate::errors::{SimError, scenario_error};
use numpy::{PyReadonlyArray1, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sim::{Command, Simulation};
use std::sync::{Mutex, TryLockError};
use systems::core::pool::KernelPool;

/// One world and its episode.
struct Slot {
    sim: Simulation,
    /// Episodes started before the current one.
    episode: u64,
    seed: u64,
    /// The episode ended at the last call: the next call starts a new one.
    ended: bool,
}

/// One world's share of a call's outputs.
#[derive(Default)]
struct Out {
    ranges: Vec<f32>,
    poses: Vec<f64>,
    twists: Vec<f64>,
    collisions: Vec<i64>,
    time: f64,
    done: bool,
    reset: bool,
    error: Option<String>,
}

struct Worlds {
    slots: Vec<Slot>,
    seed: u64,
}

/// A world started again with `seed`, then stepped `ticks` ticks (so its first observation
/// holds a scan).
fn restart(sim: &mut Simulation, seed: u64, ticks: u32) -> anyhow::Result<()> {
    sim.reset(seed)?;
    for _ in 0..ticks {
        sim.step()?;
    }
    Ok(())
}

/// N independent worlds of one scenario stepped together (see the module docs).
#[pyclass(module = "sim._sim", name = "VecSimulation", frozen)]
pub struct PyVecSimulation {
    worlds: Mutex<Worlds>,
    pool: KernelPool,
    name: String,
    robots: Vec<String>,
    beams: Vec<usize>,
    range_max: Vec<f64>,
    reset_ticks: u32,
    dt: f64,
}

/// The options a vectorized simulation takes from `Simulation(...)`'s.
const VEC_OPTIONS: &[&str] = &["duration", "set", "cache"];

impl PyVecSimulation {
    fn lock(&self) -> PyResult<std::sync::MutexGuard<'_, Worlds>> {
        match self.worlds.try_lock() {
            Ok(g) => Ok(g),
            Err(TryLockError::Poisoned(e)) => Ok(e.into_inner()),
            Err(TryLockError::WouldBlock) => Err(SimError::new_err(
                "the vectorized simulation is busy: another thread is stepping it",
            )),
        }
    }

    /// Every world's outputs as stacked arrays.
    fn stack<'py>(
        &self,
        py: Python<'py>,
        outs: Vec<Out>,
        seeds: Vec<u64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (n, r, b) = (
            outs.len(),
            self.robots.len(),
            self.beams.iter().copied().max().unwrap_or(0),
        );
        if let Some((i, e)) = outs
            .iter()
            .enumerate()
            .find_map(|(i, o)| o.error.as_ref().map(|e| (i, e)))
        {
            return Err(SimError::new_err(format!("world {i}: {e}")));
        }
        let mut ranges = Vec::with_capacity(n * r * b);
        let mut poses = Vec::with_capacity(n * r * 3);
        let mut twists = Vec::with_capacity(n * r * 2);
        let mut collisions = Vec::with_capacity(n * r);
        let (mut time, mut done, mut reset) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for o in outs {
            ranges.extend_from_slice(&o.ranges);
            poses.extend_from_slice(&o.poses);
            twists.extend_from_slice(&o.twists);
            collisions.extend_from_slice(&o.collisions);
            time.push(o.time);
            done.push(o.done);
            reset.push(o.reset);
        }
        let d = PyDict::new(py);
        d.set_item("ranges", array(py, ranges, &[n, r, b])?)?;
        d.set_item("poses", array(py, poses, &[n, r, 3])?)?;
        d.set_item("twists", array(py, twists, &[n, r, 2])?)?;
        d.set_item("collisions", array(py, collisions, &[n, r])?)?;
        d.set_item("time", array(py, time, &[n])?)?;
        d.set_item("done", array(py, done, &[n])?)?;
        d.set_item("reset", array(py, reset, &[n])?)?;
        d.set_item("seeds", array(py, seeds, &[n])?)?;
        Ok(d)
    }
}

/// A world's robots read into `out`: ranges padded with NaN to `beams`, poses, velocities and
/// collision counts.
fn observe(
    sim: &Simulation,
    robots: &[String],
    beams: usize,
    out: &mut Out,
) -> Result<(), sim::SimError> {
    out.ranges.clear();
    out.poses.clear();
    out.twists.clear();
    out.collisions.clear();
    for name in robots {
        let r = sim.robot(name)?;
        let start = out.ranges.len();
        out.ranges.resize(start + beams, f32::NAN);
        if let Some(scan) = r.scan() {
            let got = scan.ranges();
            let k = got.len().min(beams);
            out.ranges[start..start + k].copy_from_slice(&got[..k]);
        }
        let p = r.pose();
        out.poses.extend([p.x, p.y, p.theta]);
        let t = r.twist();
        out.twists.extend([t.v, t.w]);
        out.collisions.push(i64::from(r.collisions().total()));
    }
    out.time = sim.time();
    Ok(())
}

/// One call's work on one world.
struct Job<'a> {
    slot: &'a mut Slot,
    out: Out,
    index: u64,
    commands: &'a [f64],
    end: bool,
}

fn run_job(job: &mut Job<'_>, n: u64, base: u64, ticks: [u32; 2], robots: &[String], beams: usize) {
    let [ticks, reset_ticks] = ticks;
    let slot = &mut *job.slot;
    let result = (|| -> anyhow::Result<()> {
        if slot.ended || job.end {
            slot.episode += 1;
            slot.seed = base
                .wrapping_add(job.index)
                .wrapping_add(slot.episode.wrapping_mul(n));
            restart(&mut slot.sim, slot.seed, reset_ticks)?;
            slot.ended = false;
            job.out.reset = true;
        } else {
            for (k, name) in robots.iter().enumerate() {
                let (v, w) = (job.commands[2 * k], job.commands[2 * k + 1]);
                slot.sim.command(name, Command::Drive { v, w })?;
            }
            for _ in 0..ticks {
                slot.sim.step()?;
                if slot.sim.is_over() {
                    break;
                }
            }
            slot.ended = slot.sim.is_over();
        }
        observe(&slot.sim, robots, beams, &mut job.out)?;
        Ok(())
    })();
    job.out.done = slot.ended;
    if let Err(e) = result {
        job.out.error = Some(format!("{e:#}"));
    }
}

#[pymethods]
impl PyVecSimulation {
    /// `num_worlds` worlds of a bundled scenario or a scenario file; world i starts with seed
    /// `seed + i`. `threads` steps them (0: one per core); `reset_ticks` ticks run after every
    /// reset, before the episode's first observation (1: it holds a scan); options
    /// `duration`, `set` and `cache` as for `Simulation(...)`. `reset()` returns the first
    /// observations.
    #[new]
    #[pyo3(signature = (
        scenario = "maze_run", num_worlds = 8, *, seed = 0, threads = 0, reset_ticks = 0,
        **options
    ))]
    fn new(
        py: Python<'_>,
        scenario: &str,
        num_worlds: usize,
        seed: u64,
        threads: usize,
        reset_ticks: u32,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        if num_worlds == 0 {
            return Err(PyValueError::new_err(
                "num_worlds: expected at least 1 world",
            ));
        }
        if let Some(opts) = options {
            for k in opts.keys() {
                let key: String = k.extract()?;
                if !VEC_OPTIONS.contains(&key.as_str()) {
                    return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                        "unknown option `{key}` of a vectorized simulation (options: seed, \
                         threads, {}); recordings and controllers belong to single worlds",
                        VEC_OPTIONS.join(", ")
                    )));
                }
            }
        }
        let pool =
            KernelPool::new(threads).map_err(|e| PyValueError::new_err(format!("threads: {e}")))?;
        let mut builders = Vec::with_capacity(num_worlds);
        // one copy of the map's read-only structures for every world (and every reset)
        let cache = crate::simulation::Options::from_kwargs(options)?
            .map_cache()
            .sharing();
        for i in 0..num_worlds as u64 {
            let opts = crate::simulation::Options::from_kwargs(options)?;
            let b = opts.apply_plain(Simulation::load(scenario))?;
            builders.push(
                b.seed(seed.wrapping_add(i))
                    .kernel_pool(KernelPool::inline())
                    .cache(cache.clone()),
            );
        }
        // each world is built by the worker that will step it (see `step`)
        type Built = Option<anyhow::Result<Simulation>>;
        let mut built: Vec<(Option<sim::SimulationBuilder>, Built)> =
            builders.into_iter().map(|b| (Some(b), None)).collect();
        py.detach(|| {
            pool.for_each_pinned(&mut built, |(todo, done)| {
                *done = todo.take().map(|b| b.build());
            })
        });
        let mut slots = Vec::with_capacity(num_worlds);
        for (i, (_, b)) in built.into_iter().enumerate() {
            let Some(b) = b else {
                return Err(SimError::new_err(format!("world {i} was not built")));
            };
            let sim = b.map_err(scenario_error)?;
            slots.push(Slot {
                sim,
                episode: 0,
                seed: seed.wrapping_add(i as u64),
                ended: false,
            });
        }
        let sc = slots[0].sim.scenario();
        let robots: Vec<String> = sc.robots.iter().map(|r| r.name.clone()).collect();
        let beams = sc
            .robots
            .iter()
            .map(|r| r.laser.as_ref().map_or(0, |l| l.beams()))
            .collect();
        let range_max = sc
            .robots
            .iter()
            .map(|r| r.laser.as_ref().map_or(0.0, |l| l.max_range))
            .collect();
        Ok(PyVecSimulation {
            name: sc.name.clone(),
            dt: sc.dt,
            robots,
            beams,
            range_max,
            reset_ticks,
            pool,
            worlds: Mutex::new(Worlds { slots, seed }),
        })
    }

    /// Starts every world's first episode again (world i with seed `seed + i`; the seed given
    /// at construction when None): the first observations.
    #[pyo3(signature = (seed = None))]
    fn reset<'py>(&self, py: Python<'py>, seed: Option<u64>) -> PyResult<Bound<'py, PyDict>> {
        let mut worlds = self.lock()?;
        let base = seed.unwrap_or(worlds.seed);
        worlds.seed = base;
        let (robots, beams) = (&self.robots, self.beams.iter().copied().max().unwrap_or(0));
        let mut jobs: Vec<(u64, &mut Slot, Out)> = worlds
            .slots
            .iter_mut()
            .enumerate()
            .map(|(i, slot)| (i as u64, slot, Out::default()))
            .collect();
        py.detach(|| {
            self.pool.for_each_pinned(&mut jobs, |(i, slot, out)| {
                out.reset = true;
                slot.episode = 0;
                slot.seed = base.wrapping_add(*i);
                slot.ended = false;
                let r = restart(&mut slot.sim, slot.seed, self.reset_ticks)
                    .and_then(|()| observe(&slot.sim, robots, beams, out).map_err(Into::into));
                if let Err(e) = r {
                    out.error = Some(format!("{e:#}"));
                }
            })
        });
        let outs: Vec<Out> = jobs.into_iter().map(|(_, _, out)| out).collect();
        let seeds = worlds.slots.iter().map(|s| s.seed).collect();
        self.stack(py, outs, seeds)
    }

    /// Steps every world `ticks` ticks with `commands`, an `(N, R, 2)` array of `(v, w)` per
    /// robot (held through the ticks), and returns the stacked observations. A world whose
    /// episode ended at the last call (`done`), or that `end` (an `(N,)` bool array) marks,
    /// starts its next episode instead: its commands are ignored and its observation is the
    /// new episode's first (`reset` true).
    #[pyo3(signature = (commands, ticks = 1, end = None))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        commands: &Bound<'py, PyAny>,
        ticks: u32,
        end: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let mut worlds = self.lock()?;
        let (n, r) = (worlds.slots.len(), self.robots.len());
        let np = py.import("numpy")?;
        let commands = np.call_method1("asarray", (commands, "float64"))?;
        let commands: PyReadonlyArray3<f64> = commands.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "commands: expected an array of shape ({n}, {r}, 2), got {} dimensions",
                commands
                    .getattr("ndim")
                    .map_or_else(|_| "?".into(), |d| d.to_string())
            ))
        })?;
        if commands.shape() != [n, r, 2] {
            return Err(PyValueError::new_err(format!(
                "commands: expected an array of shape ({n}, {r}, 2) (worlds, robots, (v, w)), got {:?}",
                commands.shape()
            )));
        }
        let commands: Vec<f64> = commands.as_array().iter().copied().collect();
        let end: Vec<bool> = match end {
            None => vec![false; n],
            Some(e) => {
                let e = np.call_method1("asarray", (e, "bool"))?;
                let e: PyReadonlyArray1<bool> = e.extract().map_err(|_| {
                    PyValueError::new_err(format!("end: expected a bool array of shape ({n},)"))
                })?;
                if e.len() != n {
                    return Err(PyValueError::new_err(format!(
                        "end: expected a bool array of shape ({n},), got ({},)",
                        e.len()
                    )));
                }
                e.as_array().to_vec()
            }
        };
        if ticks == 0 {
            return Err(PyValueError::new_err("ticks: expected at least 1"));
        }
        let (base, beams) = (worlds.seed, self.beams.iter().copied().max().unwrap_or(0));
        let robots = &self.robots;
        let mut jobs: Vec<Job> = worlds
            .slots
            .iter_mut()
            .enumerate()
            .map(|(i, slot)| Job {
                slot,
                out: Out::default(),
                index: i as u64,
                commands: &commands[i * r * 2..(i + 1) * r * 2],
                end: end[i],
            })
            .collect();
        py.detach(|| {
            self.pool.for_each_pinned(&mut jobs, |job| {
                run_job(
                    job,
                    n as u64,
                    base,
                    [ticks, self.reset_ticks],
                    robots,
                    beams,
                )
            })
        });
        let outs: Vec<Out> = jobs.into_iter().map(|j| j.out).collect();
        let seeds = worlds.slots.iter().map(|s| s.seed).collect();
        self.stack(py, outs, seeds)
    }

    /// The number of worlds.
    #[getter]
    fn num_worlds(&self) -> PyResult<usize> {
        Ok(self.lock()?.slots.len())
    }

    /// The robots' names, in the scenario's order (the second axis of every array).
    #[getter]
    fn robot_names(&self) -> Vec<String> {
        self.robots.clone()
    }

    /// Each robot's beam count (0 without a laser); `ranges` is padded with NaN to the largest.
    #[getter]
    fn beams(&self) -> Vec<usize> {
        self.beams.clone()
    }

    /// Each robot's laser reach (m; 0 without a laser).
    #[getter]
    fn range_max(&self) -> Vec<f64> {
        self.range_max.clone()
    }

    /// The tick's length (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.dt
    }

    /// The scenario's name.
    #[getter]
    fn name(&self) -> &str {
        &self.name
    }

    /// Each world's current episode number (0 for the first).
    #[getter]
    fn episodes(&self) -> PyResult<Vec<u64>> {
        Ok(self.lock()?.slots.iter().map(|s| s.episode).collect())
    }

    /// Each world's current seed.
    #[getter]
    fn seeds(&self) -> PyResult<Vec<u64>> {
        Ok(self.lock()?.slots.iter().map(|s| s.seed).collect())
    }

    fn __repr__(&self) -> String {
        format!(
            "<sim.VecSimulation {:?}, {} robots per world>",
            self.name,
            self.robots.len()
        )
    }
}
