"""A headless multi-robot simulator for localization, mapping and navigation research.

The engine is the Rust library behind the ``sim`` command; this package drives it from
Python: load a scenario, step it, read each robot's sensors and estimators as numpy arrays,
command robots or drive them with Python controllers, and write the recordings ``sim run``
writes. The GIL is released while the engine steps.

>>> import sim
>>> s = sim.Simulation("hospital_patrol", duration=2.0, threads=1)
>>> s.run_for(0.5)
>>> s.robot("r1").ranges.shape
(541,)
>>> summary = s.run()

The guide is ``sim/docs/python.md`` in the repository.
"""

from pathlib import Path as _Path

from ._sim import (
    Estimate,
    Observation,
    Robot,
    Scan,
    ScenarioError,
    SimError,
    Simulation,
    VecSimulation,
    __version__,
    assets_dir,
    scenarios,
    use_bundled_assets as _use_bundled_assets,
)

# The wheel carries the repository's assets (scenarios, maps, roads): an installed package
# reads its own copy, and keeps working when the clone it was built from moves or is gone.
if (_Path(__file__).parent / "assets" / "scenarios").is_dir():
    _use_bundled_assets(str(_Path(__file__).parent / "assets"))

__all__ = [
    "Estimate",
    "Observation",
    "Robot",
    "Scan",
    "ScenarioError",
    "SimError",
    "Simulation",
    "VecSimulation",
    "__version__",
    "assets_dir",
    "scenarios",
]
