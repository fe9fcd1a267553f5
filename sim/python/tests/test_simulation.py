"""The scripting facade from Python: loading, stepping, reading, commanding, finishing."""

import math
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import sim
from conftest import ASSETS, verify_rrd


def test_bundled_scenarios_are_listed():
    names = sim.scenarios()
    assert "hospital_patrol" in names and "maze_run" in names


def test_the_installed_package_reads_its_own_copy_of_the_assets(tmp_path):
    own = Path(sim.__file__).parent / "assets"
    if "SIM_ASSETS" not in os.environ:
        assert sim.assets_dir() == own
    # a real folder in the installed package, not a link back into the repository
    assert own.is_dir() and not own.is_symlink()
    assert sorted(p.stem for p in (own / "scenarios").glob("*.toml")) == sim.scenarios()
    s = sim.Simulation("hospital_nav", duration=1.0, threads=1)
    s.run_for(0.5)
    assert s.ticks == 10
    # $SIM_ASSETS still wins, and a folder without scenarios is a clear error
    code = "import sim; print(sim.assets_dir()); sim.Simulation('hospital_nav')"
    env = dict(os.environ, SIM_ASSETS=str(tmp_path))
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert p.returncode != 0
    assert p.stdout.strip() == str(tmp_path)
    assert "hospital_nav" in p.stderr and str(tmp_path) in p.stderr, p.stderr


def test_reads_every_robot_between_ticks():
    s = sim.Simulation("hospital_patrol", duration=2.0, threads=1)
    assert s.robot_names == ["r1", "r2", "r3", "r4"]
    assert s.dt == pytest.approx(0.05)
    s.run_for(0.5)
    assert s.ticks == 10 and s.time == pytest.approx(0.5)
    r1 = s.robot("r1")
    x, y, theta = r1.pose
    assert all(math.isfinite(v) for v in (x, y, theta))
    ranges = r1.ranges
    assert ranges.dtype == np.float32 and ranges.ndim == 1 and len(ranges) > 100
    scan = r1.scan
    assert np.array_equal(scan.ranges, ranges)
    assert scan.angles.shape == ranges.shape
    assert scan.angles[1] - scan.angles[0] == pytest.approx(scan.angle_increment, rel=1e-4)
    assert r1.odometry is not None
    est = r1.localizer("mcl_tracking") if any(
        e.name == "mcl_tracking" for e in r1.localizers) else r1.localizers[0]
    assert est.pose is not None and est.covariance.shape == (3, 3)
    assert np.allclose(est.covariance, est.covariance.T)
    # each read sees the simulation as it is now, and the arrays are copies
    before = r1.pose
    s.run_for(0.5)
    assert r1.pose != before
    assert not np.shares_memory(ranges, r1.ranges)
    assert isinstance(s.people, list) and {"name", "pose"} <= set(s.people[0])
    summary = s.run()
    assert summary["scenario"] == "hospital_patrol"
    assert len(summary["robots"]) == 4
    assert s.finished and s.summary == summary


def test_same_seed_same_trajectory_and_reset_equals_a_fresh_world():
    def poses(s, ticks):
        out = []
        for _ in range(ticks):
            s.step()
            out.append(s.robot("scout").pose)
        return out

    a = sim.Simulation("maze_run", seed=9, threads=1)
    b = sim.Simulation("maze_run", seed=9, threads=2)
    pa = poses(a, 40)
    assert pa == poses(b, 40)
    c = sim.Simulation("maze_run", seed=1, threads=1)
    poses(c, 25)
    c.reset(9)
    assert c.ticks == 0 and c.seed == 9
    assert poses(c, 40) == pa


def test_run_until_stops_when_the_condition_holds():
    s = sim.Simulation("maze_run", threads=1)
    held = s.run_until(lambda s: s.robot("scout").pose[0] > 3.0, max_s=30.0)
    assert held and s.robot("scout").pose[0] > 3.0
    assert s.time < 30.0
    assert not s.run_until(lambda s: False, max_s=0.25)
    assert s.ticks > 0


def test_commands_drive_teleport_and_refuse_bad_values():
    s = sim.Simulation("maze_run", threads=1)
    r = s.robot("scout")
    r.drive(0.0, 0.5)
    s.run_for(1.0)
    assert r.twist[1] == pytest.approx(0.5, abs=0.05)
    r.teleport((3.25, 9.25, 0.0))
    s.step()
    assert r.pose[0] == pytest.approx(3.25, abs=0.05)
    with pytest.raises(sim.SimError, match="finite"):
        r.drive(float("nan"), 0.0)
    with pytest.raises(sim.SimError, match="no robot named `ghost` \\(robots: scout\\)"):
        s.robot("ghost")
    with pytest.raises(sim.SimError, match="obstacle|outside"):
        r.teleport((-50.0, -50.0))
    with pytest.raises(ValueError, match="expected laser, encoder or sonar"):
        r.sensor_fault("radar")
    with pytest.raises(sim.SimError, match="no task queue"):
        r.go_to((5.0, 5.0))


def test_navigation_goals_tasks_and_doors():
    s = sim.Simulation("hospital_delivery", threads=1, duration=5.0)
    r = s.robots[0]
    nav = r.navigation
    assert nav is not None and nav["tasks"] >= 1
    before = nav["tasks"]
    place = next(iter(s.places))
    r.go_to(place)
    r.wait(1.0)
    s.step()
    assert r.navigation["tasks"] == before + 2
    with pytest.raises(sim.SimError, match="no place named"):
        r.deliver("nowhere", place)
    doors = s.doors
    if doors:
        name, is_open = next(iter(doors.items()))
        s.set_door(name, not is_open)
        s.step()
        assert s.doors[name] == (not is_open)
    with pytest.raises(sim.SimError, match="no door|door"):
        s.set_door("no_such_door", True)


def test_slam_map_and_trajectory_as_arrays(maze_slam_toml):
    s = sim.Simulation.from_toml(maze_slam_toml, label="maze_slam.toml", threads=1)
    s.run_for(3.0)
    r = s.robot("scout")
    m = r.slam_map("scan_to_map")
    assert m["p"].ndim == 2 and m["p"].dtype == np.float32
    assert ((m["p"] >= 0) & (m["p"] <= 1)).all()
    assert m["resolution"] > 0
    assert r.slam_map("mcl") is None
    t = r.trajectory("scan_to_map")
    assert t.ndim == 2 and t.shape[1] == 4 and len(t) > 5
    s.finish()
    traj = s.trajectories()["scout"]
    assert traj["mcl"].shape[1] == 7


def test_tum_files_hold_every_estimate_when_asked(tmp_path):
    # a global MCL that converges after its first estimates: the default files start there
    hospital = ASSETS / "maps" / "hospital"
    toml = f"""
name = "hospital_global"
duration = 20.0
[map]
file = "{hospital / 'hospital.yaml'}"
places = "{hospital / 'places.toml'}"
[[robots]]
name = "r1"
start = "charger_1"
footprint = {{ circle = 0.3 }}
behaviour = {{ type = "waypoints", loop = true, speed = 0.8, points = [[3.8, 16.0], "pharmacy"] }}
[robots.sensors.laser]
preset = "sick_lms100"
rate = 10.0
[robots.sensors.encoder]
[[robots.localization]]
type = "mcl"
init = "global"
max_particles = 100000
"""
    s = sim.Simulation.from_toml(toml, label="hospital_global.toml")
    s.run()
    rows = s.trajectories()["r1"]["mcl"]
    every = s.write_tum(tmp_path / "all", all_estimates=True)
    judged = s.write_tum(tmp_path / "judged")
    assert len(every) == len(judged) > 0

    def times(path):
        return [float(line.split()[0]) for line in open(path)]

    all_t = times(tmp_path / "all" / "r1" / "mcl.tum")
    judged_t = times(tmp_path / "judged" / "r1" / "mcl.tum")
    assert len(all_t) == len(rows) and abs(all_t[0] - rows[0, 0]) < 1e-6
    assert 0 < len(judged_t) < len(all_t) and judged_t[-1] == all_t[-1]


def test_camera_frames_are_rgb_arrays():
    s = sim.Simulation("park_route_short", threads=1, duration=2.0)
    car = s.robots[0]
    assert car.camera is None or car.camera.ndim == 3
    s.run_for(1.0)
    img = car.camera
    assert img is not None and img.dtype == np.uint8 and img.ndim == 3 and img.shape[2] == 3
    assert img.std() > 0
    fixes = []
    for _ in range(40):
        s.step()
        fixes += car.gps
    assert fixes and {"lat", "lon", "covariance"} <= set(fixes[0])
    assert 40 < fixes[0]["lat"] < 60  # the park is in Czechia


def test_overrides_and_scenario_errors(tmp_path):
    s = sim.Simulation("maze_run", set={"robots[0].sensors.laser.increment_deg": 1.0}, threads=1)
    s.run_for(0.2)
    assert len(s.robot("scout").ranges) == 271  # 270° at 1°
    with pytest.raises(sim.ScenarioError, match="unknown field `beams`"):
        sim.Simulation("maze_run", set={"robots[0].sensors.laser.beams": 90})
    with pytest.raises(sim.ScenarioError, match="no_such_scenario"):
        sim.Simulation("no_such_scenario")
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\nduration = -1.0\n')
    with pytest.raises(sim.ScenarioError, match=r"bad.toml.*line 2|bad.toml:2"):
        sim.Simulation(str(bad))
    with pytest.raises(sim.ScenarioError, match="<mine>"):
        sim.Simulation.from_toml("duration = [", label="<mine>")
    with pytest.raises(TypeError, match="unknown option `sed` \\(options: seed, "):
        sim.Simulation("maze_run", sed=3)
    with pytest.raises(TypeError, match="option `seed`: expected an int >= 0, got str"):
        sim.Simulation("maze_run", seed="three")
    with pytest.raises(TypeError, match="option `set`: expected a dict"):
        sim.Simulation("maze_run", set=["robots[0].seed=1"])
    with pytest.raises(ValueError, match="threads"):
        sim.Simulation("maze_run", threads=100000)
    with pytest.raises(sim.ScenarioError, match="duration"):
        sim.Simulation("maze_run", duration=float("nan"))


def test_a_finished_simulation_refuses_to_step():
    s = sim.Simulation("maze_run", threads=1, duration=0.5)
    s.run()
    with pytest.raises(sim.SimError, match="finished"):
        s.step()
    with pytest.raises(sim.SimError, match="finished"):
        s.robot("scout").pose


def test_recordings_are_written_and_verify(tmp_path):
    rrd = tmp_path / "maze.rrd"
    mcap = tmp_path / "maze.mcap"
    s = sim.Simulation("maze_run", duration=1.0, threads=1, rrd=rrd, mcap=mcap)
    with pytest.raises(sim.SimError, match="recording|overwrite|restart"):
        s.reset(1)
    s.run()
    assert rrd.stat().st_size > 0 and mcap.stat().st_size > 0
    verify_rrd(rrd)


def test_the_gil_is_released_while_the_engine_steps():
    s = sim.Simulation("maze_run", threads=1)
    done = threading.Event()
    count = [0]
    during = []

    def run():
        before = count[0]
        s.run_for(60.0)
        during.append(count[0] - before)
        done.set()

    t = threading.Thread(target=run)
    t.start()
    while not done.is_set():
        count[0] += 1
    t.join()
    # with the GIL held through run_for, this thread could not count while it ran
    assert during[0] > 1000


def test_a_scenario_built_in_code_runs_and_bad_keys_are_named():
    corridor = {
        "name": "corridor",
        "duration": 2.0,
        "walls": [{"from": [0.0, 0.0], "to": [20.0, 0.0]}, {"from": [0.0, 3.0], "to": [20.0, 3.0]}],
        "robots": [
            {
                "name": "r1",
                "start": [1.0, 1.5, 0.0],
                "behaviour": {"type": "waypoints", "points": [[19.0, 1.5]], "speed": 0.8},
                "sensors": {"laser": {"preset": "sick_lms100"}, "encoder": {}},
                "localization": [{"type": "mcl", "init": "pose"}],
            }
        ],
    }
    s = sim.Simulation.from_dict(corridor, seed=2, threads=1)
    summary = s.run()
    assert summary["scenario"] == "corridor" and summary["seed"] == 2
    assert summary["robots"][0]["distance_m"] > 1.0
    corridor["robots"][0]["sensors"]["laser"]["frequency"] = 10.0
    with pytest.raises(sim.ScenarioError, match="<dict>.*frequency"):
        sim.Simulation.from_dict(corridor)
    with pytest.raises(ValueError, match="TOML has no None"):
        sim.Simulation.from_dict({"name": "x", "duration": None})
