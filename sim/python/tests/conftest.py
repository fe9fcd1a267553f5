"""Shared fixtures of the Python package's tests."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
ASSETS = REPO / "assets"

# A small world: the maze, one robot with a laser, encoders, MCL and scan-to-map SLAM.
MAZE_SLAM = f"""
name = "maze_slam"
seed = 4
dt = 0.05
duration = 6.0

[map]
file = "{ASSETS / 'maps' / 'maze' / 'maze.yaml'}"

[[robots]]
name = "scout"
start = [1.25, 1.25, 0.0]
footprint = {{ circle = 0.25 }}
behaviour = {{ type = "waypoints", loop = false, speed = 0.6, tolerance = 0.3, points = [[19.25, 1.25]] }}
[robots.sensors.laser]
preset = "sick_lms100"
rate = 10.0
[robots.sensors.encoder]
[[robots.localization]]
type = "mcl"
max_particles = 500
[[robots.slam]]
type = "scan_to_map"
"""


@pytest.fixture
def maze_slam_toml() -> str:
    return MAZE_SLAM


def rerun_cli() -> str | None:
    """The Rerun command-line tool tests/run.sh installs (SIM_RERUN_VENV), else one on PATH."""
    venv = os.environ.get("SIM_RERUN_VENV")
    if venv and (Path(venv) / "bin" / "rerun").exists():
        return str(Path(venv) / "bin" / "rerun")
    return shutil.which("rerun")


def verify_rrd(path: Path) -> None:
    """`rerun rrd verify` accepts the recording (skipped without the tool, unless required)."""
    cli = rerun_cli()
    if cli is None:
        if os.environ.get("SIM_REQUIRE_TOOLS") == "1":
            pytest.fail("SIM_REQUIRE_TOOLS=1 but the rerun CLI is missing")
        pytest.skip("the rerun CLI is not installed")
    out = subprocess.run([cli, "rrd", "verify", str(path)], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr
