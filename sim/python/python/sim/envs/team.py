"""Multi-robot point-goal navigation in the hospital as a PettingZoo ``ParallelEnv``.

Each robot of ``hospital_nav_team`` is an agent with the single-robot task of ``_task``: its
own goal, drawn per episode among the places near its start, its laser and the goal in its
frame as observation, ``(v, w)`` scaled from [-1, 1]² as action. An agent leaves the episode when it reaches its
goal or collides (its robot then stands still); the episode is truncated for all after
``max_steps`` steps.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from gymnasium import spaces as gym_spaces
from gymnasium.utils import seeding
from pettingzoo import ParallelEnv

import sim

from ._task import (
    TEAM_SCENARIO,
    GoalSampler,
    NavConfig,
    command,
    goal_in_robot_frame,
    observation,
    reward,
    spaces,
)


class HospitalTeamNavEnv(ParallelEnv):
    """Every robot an agent sent to a place of the hospital (see the module docs)."""

    metadata = {"name": "sim_hospital_team_nav_v0", "render_modes": []}

    def __init__(self, config: NavConfig | None = None, threads: int = 1):
        self.cfg = config or NavConfig(scenario=TEAM_SCENARIO)
        self._sim = sim.Simulation(self.cfg.scenario, threads=threads)
        self.possible_agents = list(self._sim.robot_names)
        self.agents: list[str] = []
        self._robots = {r.name: r for r in self._sim.robots}
        self._range_max = {}
        self._spaces = {}
        self._goals = {}
        for name, r in self._robots.items():
            laser = r.laser
            if laser is None:
                raise sim.SimError(f"scenario `{self.cfg.scenario}`: robot `{name}` has no laser")
            self._range_max[name] = float(laser["max_range"])
            self._spaces[name] = spaces(gym_spaces, int(laser["beams"]), self._range_max[name], self.cfg)
            self._goals[name] = GoalSampler(self._sim.places, r.pose, self.cfg)
        self._rng, _ = seeding.np_random(None)
        self._goal: dict[str, np.ndarray] = {}
        self._dist: dict[str, float] = {}
        self._collisions: dict[str, int] = {}
        self._steps = 0

    @functools.cache
    def observation_space(self, agent: str):
        return self._spaces[agent][0]

    @functools.cache
    def action_space(self, agent: str):
        return self._spaces[agent][1]

    def _observe(self, agent: str):
        r = self._robots[agent]
        pose = np.array(r.pose)
        ranges = r.ranges
        if ranges is None:
            ranges = np.full(self._spaces[agent][0].shape[0] - 2, np.nan, dtype=np.float32)
        obs = observation(
            ranges, self._range_max[agent], pose, self._goal[agent], self.cfg.max_distance
        )
        return obs, float(goal_in_robot_frame(pose, self._goal[agent])[0])

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None):
        if seed is not None:
            self._rng, _ = seeding.np_random(seed)
        self._sim.reset(int(self._rng.integers(2**63)))
        self._sim.step()  # the first observations hold a scan
        self.agents = list(self.possible_agents)
        observations, infos = {}, {}
        for a in self.agents:
            name, self._goal[a] = self._goals[a].draw(self._rng)
            observations[a], self._dist[a] = self._observe(a)
            self._collisions[a] = self._robots[a].collisions["total"]
            infos[a] = {"goal": name, "distance": self._dist[a]}
        self._steps = 0
        return observations, infos

    def step(self, actions: dict[str, Any]):
        for a in self.agents:
            if a not in actions:
                raise ValueError(f"no action for agent `{a}` (agents: {', '.join(self.agents)})")
            v, w = command(self.cfg, actions[a])
            self._robots[a].drive(float(v), float(w))
        self._sim.run_for(self.cfg.ticks_per_step * self._sim.dt)
        self._steps += 1
        obs, rewards, terms, truncs, infos = {}, {}, {}, {}, {}
        for a in self.agents:
            obs[a], dist = self._observe(a)
            total = self._robots[a].collisions["total"]
            collided = total > self._collisions[a]
            self._collisions[a] = total
            reached = dist <= self.cfg.goal_radius
            rewards[a] = float(reward(self.cfg, self._dist[a], dist, collided, reached))
            self._dist[a] = dist
            terms[a] = bool(reached or collided)
            truncs[a] = bool(not terms[a] and self._steps >= self.cfg.max_steps)
            infos[a] = {"distance": dist, "collided": bool(collided)}
        for a in list(self.agents):
            if terms[a] or truncs[a]:
                self._robots[a].drive(0.0, 0.0)  # out of the episode: it stands still
        self.agents = [a for a in self.agents if not (terms[a] or truncs[a])]
        return obs, rewards, terms, truncs, infos
