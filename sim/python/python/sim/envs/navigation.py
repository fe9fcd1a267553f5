"""Point-goal navigation in the hospital as a Gymnasium environment, and its vectorized form.

The task is in ``_task``: the robot starts at the scenario's start, is sent to a place drawn
per episode, and sees its laser and the goal in its own frame. An action in [-1, 1]² scales
to ``(v, w)`` (``NavConfig``'s limits) and is held for ``ticks_per_step`` engine ticks.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces as gym_spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

import sim

from ._task import (
    GoalSampler,
    NavConfig,
    command,
    goal_in_robot_frame,
    observation,
    reward,
    spaces,
)

_SEEDS = 2**63
"""Engine seeds are drawn below this from the environment's generator."""


class HospitalNavEnv(gym.Env):
    """One robot sent to a place of the hospital each episode (see the module docs)."""

    metadata = {"render_modes": []}

    def __init__(self, config: NavConfig | None = None, threads: int = 1):
        self.cfg = config or NavConfig()
        self._sim = sim.Simulation(self.cfg.scenario, threads=threads)
        self._robot = self._sim.robots[0]
        laser = self._robot.laser
        if laser is None:
            raise sim.SimError(f"scenario `{self.cfg.scenario}`: its robot has no laser")
        self._range_max = float(laser["max_range"])
        self.observation_space, self.action_space = spaces(
            gym_spaces, int(laser["beams"]), self._range_max, self.cfg
        )
        self._goals = GoalSampler(self._sim.places, self._robot.pose, self.cfg)
        self._goal = np.zeros(2)
        self._steps = 0
        self._dist = 0.0
        self._collisions = 0

    def _observe(self):
        r = self._robot
        pose = np.array(r.pose)
        ranges = r.ranges
        if ranges is None:
            ranges = np.full(self.observation_space.shape[0] - 2, np.nan, dtype=np.float32)
        obs = observation(ranges, self._range_max, pose, self._goal, self.cfg.max_distance)
        return obs, pose

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        self._sim.reset(int(self.np_random.integers(_SEEDS)))
        self._sim.step()  # the first observation holds a scan
        name, self._goal = self._goals.draw(self.np_random)
        obs, pose = self._observe()
        self._dist = float(goal_in_robot_frame(pose, self._goal)[0])
        self._steps = 0
        self._collisions = self._robot.collisions["total"]
        return obs, {"goal": name, "distance": self._dist}

    def step(self, action):
        v, w = command(self.cfg, action)
        self._robot.drive(float(v), float(w))
        self._sim.run_for(self.cfg.ticks_per_step * self._sim.dt)
        self._steps += 1
        obs, pose = self._observe()
        dist = float(goal_in_robot_frame(pose, self._goal)[0])
        total = self._robot.collisions["total"]
        collided = total > self._collisions
        self._collisions = total
        reached = dist <= self.cfg.goal_radius
        r = float(reward(self.cfg, self._dist, dist, collided, reached))
        self._dist = dist
        terminated = bool(reached or collided)
        truncated = bool(not terminated and self._steps >= self.cfg.max_steps)
        return obs, r, terminated, truncated, {"distance": dist, "collided": bool(collided)}


class HospitalNavVectorEnv(VectorEnv):
    """``num_envs`` copies of ``HospitalNavEnv`` on one ``sim.VecSimulation``, stepped together
    on the engine's threads. Autoreset mode ``NEXT_STEP``: after an episode ends, the next
    ``step`` ignores that environment's action and returns the first observation of its next
    episode (reward 0, neither terminated nor truncated)."""

    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 8, config: NavConfig | None = None, threads: int = 0):
        self.cfg = config or NavConfig()
        self.num_envs = num_envs
        self._v = sim.VecSimulation(self.cfg.scenario, num_envs, threads=threads, reset_ticks=1)
        if len(self._v.robot_names) != 1 or self._v.beams[0] == 0:
            raise sim.SimError(
                f"scenario `{self.cfg.scenario}`: expected one robot with a laser"
            )
        self._range_max = self._v.range_max[0]
        self.single_observation_space, self.single_action_space = spaces(
            gym_spaces, self._v.beams[0], self._range_max, self.cfg
        )
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        probe = sim.Simulation(self.cfg.scenario, threads=1)
        self._goals = GoalSampler(probe.places, probe.robots[0].pose, self.cfg)
        self._goal = np.zeros((num_envs, 2))
        self._names = [""] * num_envs
        self._dist = np.zeros(num_envs)
        self._steps = np.zeros(num_envs, dtype=np.int64)
        self._collisions = np.zeros(num_envs, dtype=np.int64)
        self._ended = np.zeros(num_envs, dtype=bool)

    def _new_goals(self, mask):
        for i in np.flatnonzero(mask):
            self._names[i], self._goal[i] = self._goals.draw(self.np_random)

    def _observe(self, o):
        pose = o["poses"][:, 0]
        obs = observation(o["ranges"][:, 0], self._range_max, pose, self._goal, self.cfg.max_distance)
        return obs, goal_in_robot_frame(pose, self._goal)[:, 0]

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        o = self._v.reset(int(self.np_random.integers(_SEEDS - 2**32)))
        self._new_goals(np.ones(self.num_envs, dtype=bool))
        obs, self._dist = self._observe(o)
        self._steps[:] = 0
        self._collisions[:] = o["collisions"][:, 0]
        self._ended[:] = False
        return obs, {"goal": np.array(self._names), "distance": self._dist.copy()}

    def step(self, actions):
        a = np.asarray(actions, dtype=np.float64)
        if a.shape != (self.num_envs, 2):
            raise ValueError(f"actions: expected shape ({self.num_envs}, 2), got {a.shape}")
        c = command(self.cfg, a)
        o = self._v.step(c[:, None, :], ticks=self.cfg.ticks_per_step, end=self._ended)
        restarted = o["reset"]
        self._new_goals(restarted)
        obs, dist = self._observe(o)
        total = o["collisions"][:, 0]
        collided = (total > self._collisions) & ~restarted
        reached = (dist <= self.cfg.goal_radius) & ~restarted
        r = reward(self.cfg, self._dist, dist, collided, reached)
        r = np.where(restarted, 0.0, r)
        self._steps = np.where(restarted, 0, self._steps + 1)
        terminated = reached | collided
        truncated = ~terminated & ~restarted & ((self._steps >= self.cfg.max_steps) | o["done"])
        self._dist, self._collisions = dist, total
        self._ended = terminated | truncated
        info = {"distance": dist.copy(), "collided": collided, "goal": np.array(self._names)}
        return obs, r, terminated, truncated, info
