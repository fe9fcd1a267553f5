"""Every example runs, and does what it says."""

import importlib.util
import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_example_is_tested_here():
    tested = {"scripted_hospital", "maze_controller", "parameter_sweep", "vector_rollout"}
    assert {p.stem for p in EXAMPLES.glob("*.py")} == tested


def test_scripted_hospital_reacts_to_the_robots():
    r = load("scripted_hospital").run(60.0)
    door = r["door_closed_at"]
    assert door is not None, "r1 reached the pharmacy within a minute"

    def fired(who, what, after):
        return any(robot == who and w.startswith(what) and t >= after for t, robot, w in r["log"])

    assert fired("", "door fire_door_w closed", door), r["log"]
    assert fired("r2", "new tasks: go_ward_3", door), r["log"]
    kidnapped = r["kidnapped_at"]
    assert kidnapped is not None and kidnapped >= 5.0, "r3's MCL converged (held for 5 s)"
    assert fired("r3", "teleported", kidnapped), r["log"]


def test_maze_controller_follows_the_wall(tmp_path):
    rrd = tmp_path / "maze.rrd"
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / "maze_controller.py"), "30", str(rrd)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.startswith("drove "), out.stdout
    driven = float(out.stdout.split()[1])
    assert driven > 8.0, out.stdout
    assert rrd.stat().st_size > 0


def test_parameter_sweep_gives_a_row_per_run():
    rows = load("parameter_sweep").sweep(10.0)
    assert len(rows) == 9
    assert {r["particles"] for r in rows} == {200, 1000, 5000}
    assert all(r["ate_m"] is None or r["ate_m"] >= 0 for r in rows)


def test_vector_rollout_reports_its_rate():
    r = load("vector_rollout").rollout(4, 60, 2)
    assert r["env_steps_per_s"] > 0 and r["episodes"] >= 0
