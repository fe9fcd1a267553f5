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
    scenarios,
)

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
    "scenarios",
]
