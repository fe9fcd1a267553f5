"""Learning environments on the simulator: point-goal navigation in the hospital.

- ``HospitalNavEnv``: a Gymnasium environment, one robot;
- ``HospitalNavVectorEnv``: its vectorized form (``gymnasium.vector.VectorEnv``) on
  ``sim.VecSimulation``, autoreset ``NEXT_STEP``;
- ``HospitalTeamNavEnv``: a PettingZoo ``ParallelEnv``, each of three robots an agent.

They need the optional extras: ``pip install ./sim/python[gym]``. Importing this module
registers ``sim/HospitalNav-v0`` with Gymnasium.
"""

try:
    import gymnasium as _gym
except ImportError as e:  # pragma: no cover - exercised without the extras
    raise ImportError(
        "sim.envs needs gymnasium (and pettingzoo for the multi-robot environment): "
        "pip install ./sim/python[gym]"
    ) from e

from ._task import NavConfig
from .navigation import HospitalNavEnv, HospitalNavVectorEnv

__all__ = ["HospitalNavEnv", "HospitalNavVectorEnv", "HospitalTeamNavEnv", "NavConfig"]

if "sim/HospitalNav-v0" not in _gym.registry:
    _gym.register(
        id="sim/HospitalNav-v0",
        entry_point="sim.envs.navigation:HospitalNavEnv",
        vector_entry_point="sim.envs.navigation:HospitalNavVectorEnv",
    )


def __getattr__(name):
    # pettingzoo is imported only when its environment is asked for
    if name == "HospitalTeamNavEnv":
        from .team import HospitalTeamNavEnv

        return HospitalTeamNavEnv
    raise AttributeError(name)
