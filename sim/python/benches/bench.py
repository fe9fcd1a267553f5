"""Python-side benchmarks of the package: the figures of sim/docs/benchmarks.md, "Python".

Run on an idle machine (the figures move with anything else running):

    python sim/python/benches/bench.py [--json]

1. step() overhead: a one-robot world stepped by `step()` calls against the same world
   stepped by one `run_for` call (the engine's own tick); the difference per tick is the
   cost of crossing into Python and back.
2. A Python loop driving one robot with a 1081-beam laser at dt 0.1 s in a 50 x 50 m room
   with 20 boxes (IR-SIM's benchmark world: its robots circle at v 0.5 m/s, w 0.1 rad/s and
   are driven by `env.step()` in a Python loop): the real-time factor.
3. `reset()` of the Gymnasium environment (needs the `gym` extra), in milliseconds.
4. 64 one-robot worlds in one `VecSimulation` on 1 and 2 threads against one world's
   engine throughput (ticks/s of `run_for`).

Each figure is the median of several repetitions.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time

import numpy as np

import sim

REPEATS = 7


def cpu_name() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def median_of(f, repeats=None):
    return statistics.median(f() for _ in range(repeats or REPEATS))


def room_toml(dt: float, beams_increment_deg: float = 0.25) -> str:
    """A 50 x 50 m walled room with 20 boxes and one robot with a 270-degree laser."""
    rng = np.random.default_rng(7)
    boxes = []
    while len(boxes) < 20:
        x, y = rng.uniform(4.0, 46.0, size=2)
        if np.hypot(x - 25.0, y - 25.0) < 8.0:
            continue  # keep the robot's circle clear
        w, h = rng.uniform(1.0, 4.0, size=2)
        boxes.append(f"{{ center = [{x:.2f}, {y:.2f}], size = [{w:.2f}, {h:.2f}] }}")
    return f"""
name = "room_50m"
dt = {dt}
duration = 100000.0
walls = [
  {{ from = [0.0, 0.0], to = [50.0, 0.0] }}, {{ from = [50.0, 0.0], to = [50.0, 50.0] }},
  {{ from = [50.0, 50.0], to = [0.0, 50.0] }}, {{ from = [0.0, 50.0], to = [0.0, 0.0] }},
]
boxes = [{", ".join(boxes)}]

[[robots]]
name = "robot"
start = [25.0, 20.0, 0.0]
footprint = {{ circle = 0.2 }}
behaviour = {{ type = "idle" }}
[robots.sensors.laser]
preset = "sick_lms100"
increment_deg = {beams_increment_deg}
rate = {1.0 / dt}
"""


def step_overhead(ticks=2000) -> dict:
    s = sim.Simulation("hospital_nav", threads=1)
    s.robot("robot").drive(0.5, 0.1)
    s.run_for(1.0)

    def by_step():
        t = time.perf_counter()
        for _ in range(ticks):
            s.step()
        return (time.perf_counter() - t) / ticks

    def by_run_for():
        t = time.perf_counter()
        s.run_for(ticks * s.dt)
        return (time.perf_counter() - t) / ticks

    step_s = median_of(by_step)
    engine_s = median_of(by_run_for)
    return {
        "bench": "step_overhead",
        "engine_tick_us": engine_s * 1e6,
        "step_call_us": step_s * 1e6,
        "overhead_us": (step_s - engine_s) * 1e6,
    }


def python_loop_rtf(steps=1000) -> dict:
    dt = 0.1
    s = sim.Simulation.from_toml(room_toml(dt), label="room_50m", threads=1)
    r = s.robot("robot")

    def loop():
        t = time.perf_counter()
        for _ in range(steps):
            r.drive(0.5, 0.1)
            s.step()
            r.ranges  # the scan, as a user's loop reads it
        return steps * dt / (time.perf_counter() - t)

    rtf = median_of(loop)
    return {"bench": "python_loop", "beams": len(r.ranges), "dt": dt, "real_time_factor": rtf}


def gym_reset_ms() -> dict | None:
    try:
        from sim.envs import HospitalNavEnv
    except ImportError:
        return None
    env = HospitalNavEnv()
    env.reset(seed=0)
    seeds = iter(range(1, 1000))

    def once():
        t = time.perf_counter()
        env.reset(seed=next(seeds))
        return (time.perf_counter() - t) * 1e3

    return {"bench": "gym_reset", "reset_ms": median_of(once, 2 * REPEATS + 1)}


def vector_throughput(worlds=64, ticks=200, rounds=REPEATS) -> list[dict]:
    """World ticks per second of one world driven by `run_for` and of `worlds` worlds in one
    `VecSimulation` on 1 and 2 threads. Every repetition starts each world from its episode's
    first tick and drives it the same way for `ticks` ticks, so all three do the same work per
    world tick; the three take turns within each round, so a slow spell of the machine falls on
    all of them."""
    one = sim.Simulation("hospital_nav", threads=1)
    vecs = {threads: sim.VecSimulation("hospital_nav", worlds, threads=threads) for threads in (1, 2)}
    cmd = np.tile([0.5, 0.1], (worlds, 1, 1))
    rates: dict[object, list[float]] = {"one": [], 1: [], 2: []}
    for k in range(rounds):
        one.reset(k)
        one.robot("robot").drive(0.5, 0.1)
        t = time.perf_counter()
        one.run_for(ticks * one.dt)
        rates["one"].append(ticks / (time.perf_counter() - t))
        for threads, v in vecs.items():
            v.reset(k * worlds)
            t = time.perf_counter()
            for _ in range(ticks // 10):
                v.step(cmd, ticks=10)
            rates[threads].append(worlds * (ticks // 10) * 10 / (time.perf_counter() - t))
    rows = [{"bench": "vector", "worlds": 1, "threads": 1, "world_ticks_per_s": statistics.median(rates["one"])}]
    for threads in (1, 2):
        rows.append(
            {
                "bench": "vector",
                "worlds": worlds,
                "threads": threads,
                "world_ticks_per_s": statistics.median(rates[threads]),
            }
        )
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--json", action="store_true", help="one JSON row per figure")
    a = p.parse_args()
    machine = {"cpu": cpu_name(), "cores": os.cpu_count(), "python": platform.python_version()}
    rows = [step_overhead(), python_loop_rtf()]
    g = gym_reset_ms()
    if g:
        rows.append(g)
    rows += vector_throughput()
    for row in rows:
        row.update(machine)
        print(json.dumps(row) if a.json else row)


if __name__ == "__main__":
    main()
