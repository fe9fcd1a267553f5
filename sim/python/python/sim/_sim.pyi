"""Type stubs of the native module (``sim._sim``); the names are re-exported by ``sim``."""

import pathlib
from collections.abc import Callable, Mapping
from os import PathLike
from typing import Any, TypedDict, Unpack

import numpy as np
import numpy.typing as npt

__version__: str

Pose = tuple[float, float, float]
"""A pose ``(x, y, theta)``: metres and radians, world frame."""

Controller = Callable[["Observation"], tuple[float, float]]
"""A robot's driver: given its observation each tick, returns ``(v, w)`` (m/s, rad/s)."""

class Options(TypedDict, total=False):
    """The keyword options of ``Simulation(...)``, ``Simulation.load`` and ``from_toml``."""

    seed: int
    """The random seed (default: the scenario's)."""
    duration: float
    """Seconds to simulate (default: the scenario's)."""
    threads: int
    """The engine's threads, 0 (default) for one per core; results do not depend on it."""
    set: Mapping[str, str | int | float | bool]
    """Overrides as ``sim run --set KEY=VALUE``: ``{"robots[0].seed": 3}``."""
    rrd: str | PathLike[str]
    """Write a Rerun recording here."""
    mcap: str | PathLike[str]
    """Write an MCAP replay (ROS 2 messages) here."""
    carmen: str | PathLike[str]
    """Write CARMEN logs here."""
    save_map: str | PathLike[str]
    """Save the maps here at the end."""
    controllers: Mapping[str, Controller]
    """Python controllers by robot name."""
    cache: bool
    """Use the on-disk cache of map-derived structures (default True)."""

class SimError(Exception):
    """The engine refused a request: an unknown robot, place, door or localizer, a value out
    of range, a simulation that is finished or busy."""

class ScenarioError(SimError):
    """A scenario that cannot be loaded: its file, line and key, and what was expected."""

def scenarios() -> list[str]:
    """The bundled scenarios' names."""

def assets_dir() -> pathlib.Path:
    """The folder the bundled scenarios, maps and roads are read from: ``$SIM_ASSETS`` when
    set, else the copy inside this package, else the repository the package was built from."""

def use_bundled_assets(dir: str) -> None:
    """Called once by the package itself: its own copy of the assets."""

class Simulation:
    """A running simulation of one scenario: step it, read its robots, command them, and
    finish it for its summary."""

    def __init__(
        self,
        scenario: str = "hospital_patrol",
        **options: Unpack[Options],
    ) -> None:
        """A bundled scenario by name or a scenario file, built and ready for its first tick;
        the options are those of ``Options``."""

    @staticmethod
    def load(
        scenario: str,
        **options: Unpack[Options],
    ) -> Simulation:
        """The same as ``Simulation(scenario, ...)``."""

    @staticmethod
    def from_toml(
        text: str,
        *,
        label: str = "<string>",
        relative_to: str | PathLike[str] | None = None,
        **options: Unpack[Options],
    ) -> Simulation:
        """Scenario TOML text, called ``label`` in error messages; relative paths start from
        ``relative_to`` (default: the current folder)."""

    @staticmethod
    def from_dict(
        scenario: Mapping[str, Any],
        *,
        relative_to: str | PathLike[str] | None = None,
        **options: Unpack[Options],
    ) -> Simulation:
        """A scenario built in code: nested dicts and lists with the file's structure, checked
        as a file is (errors name the key)."""

    @property
    def name(self) -> str:
        """The scenario's name."""
    @property
    def dt(self) -> float:
        """The tick's length (s)."""
    @property
    def seed(self) -> int:
        """The scenario's seed."""
    @property
    def time(self) -> float:
        """Simulated time (s): the start of the next tick."""
    @property
    def ticks(self) -> int:
        """Ticks run so far."""
    @property
    def end_tick(self) -> int:
        """The ticks of the scenario's duration."""
    @property
    def is_over(self) -> bool:
        """The scenario's duration is over, or its tasks are all done."""
    @property
    def finished(self) -> bool:
        """Whether the run has been finished."""
    @property
    def robot_names(self) -> list[str]:
        """The robots' names, in the scenario's order."""
    @property
    def robots(self) -> list[Robot]:
        """Every robot, in the scenario's order."""
    @property
    def people(self) -> list[dict[str, Any]]:
        """The walking people: dicts of ``name``, ``pose`` and ``next_point``."""
    @property
    def doors(self) -> dict[str, bool]:
        """The doors: ``{name: open}``."""
    @property
    def places(self) -> dict[str, Pose]:
        """The places of the scenario's map."""
    @property
    def summary(self) -> dict[str, Any] | None:
        """The summary of a finished run, None while it runs."""
    @property
    def log(self) -> list[tuple[float, str, str]]:
        """The finished run's events: ``(time, robot or "", text)``."""

    def step(self) -> None:
        """One tick of the schedule (the GIL released)."""
    def run_for(self, seconds: float) -> None:
        """Steps ``seconds`` of simulated time (whole ticks), even past the duration."""
    def run_until(self, done: Callable[[Simulation], bool], max_s: float) -> bool:
        """Steps until ``done(simulation)`` holds (checked before every tick) or ``max_s``
        seconds have passed; whether ``done`` held."""
    def run(self) -> dict[str, Any]:
        """Steps to the scenario's end and finishes the run; its summary."""
    def finish(self) -> dict[str, Any]:
        """Ends the run where it is (recordings and exports written); its summary."""
    def trajectories(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]:
        """The finished run's estimates beside the truth: ``{robot: {localizer: array}}``,
        rows ``(t, x, y, theta, true_x, true_y, true_theta)``."""
    def write_tum(
        self, dir: str | PathLike[str], *, all_estimates: bool = False
    ) -> list[str]:
        """Writes the finished run's trajectories as TUM files (``DIR/<robot>/<localizer>.tum``
        and ``.truth.tum``): from convergence on, or with ``all_estimates`` every estimate from
        the first; the files written."""
    def reset(self, seed: int) -> None:
        """Starts again from the first tick with ``seed``, as a new simulation would."""
    def robot(self, name: str) -> Robot:
        """The robot called ``name``."""
    def set_door(self, name: str, open: bool) -> None:
        """Opens or closes a door at the next tick."""

class Robot:
    """One robot: its state read when asked, and its commands (given between ticks)."""

    @property
    def name(self) -> str:
        """The robot's name in the scenario."""
    @property
    def index(self) -> int:
        """Its place in the scenario's robot list."""
    @property
    def pose(self) -> Pose:
        """The true pose (ground truth)."""
    @property
    def twist(self) -> tuple[float, float]:
        """The true velocity ``(v, w)`` (m/s, rad/s)."""
    @property
    def odometry(self) -> Pose | None:
        """The pose integrated from the wheel encoders, or None without encoders."""
    @property
    def laser(self) -> dict[str, float | int] | None:
        """The laser's ``beams``, ``fov``, ``increment``, ``min_range``, ``max_range``,
        ``rate``; None without a laser (read from the simulation's robot only)."""
    @property
    def scan(self) -> Scan | None:
        """The latest laser scan, or None."""
    @property
    def ranges(self) -> npt.NDArray[np.float32] | None:
        """The latest scan's ranges (m; inf for no return), or None."""
    @property
    def encoder(self) -> npt.NDArray[np.int64]:
        """The last tick's encoder readings: rows of ``(left_ticks, right_ticks)``."""
    @property
    def encoder_readings(self) -> list[dict[str, float | int]]:
        """The last tick's encoder readings: ``stamp``, ``left_ticks``, ``right_ticks``,
        ``steer``."""
    @property
    def sonar(self) -> npt.NDArray[np.float32] | None:
        """The latest sonar ranges (m, one per mount), or None."""
    @property
    def gps(self) -> list[dict[str, Any]]:
        """The last tick's GPS fixes: ``stamp``, ``lat``, ``lon``, ``altitude``,
        ``covariance``."""
    @property
    def compass(self) -> list[dict[str, float]]:
        """The last tick's compass readings: ``stamp``, ``azimuth``, ``variance``."""
    @property
    def camera(self) -> npt.NDArray[np.uint8] | None:
        """The latest camera frame, ``H × W × 3`` RGB, or None."""
    @property
    def localizers(self) -> list[Estimate]:
        """Every localizer's and SLAM system's latest estimate."""
    def localizer(self, name: str) -> Estimate:
        """The latest estimate of the localizer or SLAM system ``name``."""
    def slam_map(self, name: str) -> dict[str, Any] | None:
        """A SLAM system's map: ``p`` (P(occupied), ``p[row, col]`` from the map's bottom
        row), ``resolution`` and ``origin``; None for a localizer."""
    def trajectory(self, name: str) -> npt.NDArray[np.float64]:
        """A SLAM system's best trajectory so far: rows ``(t, x, y, theta)``."""
    @property
    def navigation(self) -> dict[str, Any] | None:
        """The navigator's ``tasks_done``, ``tasks``, ``finished``, ``phase``, ``status``;
        None for a robot driven by a behaviour."""
    @property
    def collisions(self) -> dict[str, int]:
        """Collisions so far: ``wall``, ``robot``, ``person``, ``total``."""
    @property
    def distance(self) -> float:
        """Distance driven so far (m)."""

    def drive(self, v: float, w: float) -> None:
        """Holds the velocity command ``(v, w)`` from the next tick until replaced or released."""
    def steer(self, speed: float, steer: float) -> None:
        """A car's held command: forward speed (m/s) and steering angle (rad)."""
    def release(self) -> None:
        """Drops the held command."""
    def teleport(self, pose: tuple[float, float] | Pose) -> None:
        """Carries the robot to ``pose`` without telling its estimators."""
    def waypoints(self, points: list[tuple[float, float]], looping: bool = False) -> None:
        """A new route for a robot driven by a behaviour."""
    def go_to(self, to: str | tuple[float, float]) -> None:
        """Sends a navigating robot to a place or a point, after its tasks."""
    def deliver(
        self,
        pickup: str | tuple[float, float],
        dropoff: str | tuple[float, float],
        load: float = 20.0,
        unload: float = 30.0,
        name: str | None = None,
    ) -> None:
        """Appends a delivery to a navigating robot's tasks."""
    def wait(self, seconds: float, name: str | None = None) -> None:
        """Appends a wait where the robot is to a navigating robot's tasks."""
    def sensor_fault(self, sensor: str, active: bool = True) -> None:
        """Silences ``laser``, ``encoder`` or ``sonar`` (or, ``active=False``, restores it)."""

class Scan:
    """A laser scan as the sensor reported it."""

    stamp: float
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    ranges: npt.NDArray[np.float32]
    sensor_pose: Pose | None
    @property
    def angles(self) -> npt.NDArray[np.float32]:
        """The beam angles in the sensor frame (rad)."""

class Estimate:
    """A localizer's or SLAM system's latest estimate."""

    name: str
    kind: str
    stamp: float | None
    pose: Pose | None
    covariance: npt.NDArray[np.float64] | None
    converged_after: float | None
    degraded: bool
    """True while the robot's laser is faulted: the last estimate carried by the odometry."""

class Observation:
    """What a controller sees at a tick; valid during its call only."""

    time: float
    dt: float
    tick: int
    robot: Robot

class VecSimulation:
    """N independent worlds of one scenario stepped together on the engine's thread pool.

    Episode k of world i runs with seed ``seed + i + k * N``. A world whose episode ended at
    the last call (``done``), or that ``end`` marks, starts its next episode at the next
    ``step`` (Gymnasium's ``NEXT_STEP`` autoreset): its commands are ignored and its
    observation is the new episode's first (``reset`` true). World i with seed s follows the
    trajectory of ``Simulation(scenario, seed=s)`` given the same commands, whatever N and the
    thread count.

    Observations are dicts of stacked arrays: ``ranges`` (N, R, B) float32 (each robot's scan
    padded with NaN to the largest beam count B; NaN throughout without a laser), ``poses``
    (N, R, 3), ``twists`` (N, R, 2), ``collisions`` (N, R) int64 (this episode's so far),
    ``time`` (N,), ``done`` (N,) bool, ``reset`` (N,) bool and ``seeds`` (N,) uint64.
    """

    def __init__(
        self,
        scenario: str = "maze_run",
        num_worlds: int = 8,
        *,
        seed: int = 0,
        threads: int = 0,
        reset_ticks: int = 0,
        duration: float | None = None,
        set: Mapping[str, str | int | float | bool] | None = None,
        cache: bool = True,
    ) -> None: ...
    def reset(self, seed: int | None = None) -> dict[str, npt.NDArray[Any]]:
        """Every world's first episode again (world i with seed ``seed + i``)."""
    def step(
        self,
        commands: npt.ArrayLike,
        ticks: int = 1,
        end: npt.ArrayLike | None = None,
    ) -> dict[str, npt.NDArray[Any]]:
        """Steps every world ``ticks`` ticks with ``commands`` of shape (N, R, 2), ``(v, w)``
        per robot; ``end`` (N,) bool ends episodes the caller decided are over."""
    @property
    def num_worlds(self) -> int: ...
    @property
    def robot_names(self) -> list[str]: ...
    @property
    def beams(self) -> list[int]:
        """Each robot's beam count (0 without a laser)."""
    @property
    def range_max(self) -> list[float]:
        """Each robot's laser reach (m; 0 without a laser)."""
    @property
    def dt(self) -> float: ...
    @property
    def name(self) -> str: ...
    @property
    def episodes(self) -> list[int]:
        """Each world's current episode number (0 for the first)."""
    @property
    def seeds(self) -> list[int]:
        """Each world's current seed."""
