"""Point-goal navigation in the hospital: what the environments share.

A robot starts at the scenario's start pose and is given a goal, a place of the hospital
drawn per episode. It sees its laser (ranges clipped to the sensor's reach) and the goal in
its own frame (distance, bearing). It is rewarded for progress towards the goal, pays for
time and collisions, and the episode ends at the goal (within ``goal_radius``), at a
collision, or after ``max_steps`` steps (truncated).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import sim

SCENARIO = "hospital_nav"
"""The bundled scenario of the single-robot environments: one robot with a 91-beam laser."""

TEAM_SCENARIO = "hospital_nav_team"
"""The bundled scenario of the multi-robot environment: three such robots."""


@dataclass(frozen=True)
class NavConfig:
    """The task's parameters."""

    scenario: str = SCENARIO
    ticks_per_step: int = 2
    """Engine ticks per environment step (0.05 s each)."""
    max_steps: int = 600
    goal_radius: float = 0.5
    """Reached within this distance (m)."""
    max_goal_distance: float = 15.0
    """Goals are places at most this far from the start (m)."""
    progress_reward: float = 1.0
    """Per metre of progress towards the goal."""
    goal_reward: float = 10.0
    collision_penalty: float = 10.0
    step_penalty: float = 0.01
    max_v: float = 1.0
    """Forward speed at action ``(1, ·)`` (m/s)."""
    min_v: float = -0.3
    """Speed at action ``(-1, ·)`` (m/s): reversing is slow."""
    max_w: float = 1.5
    """Yaw rate at action ``(·, ±1)`` (rad/s)."""
    max_distance: float = 100.0
    """The goal distance observed is clipped here (m)."""


def goal_in_robot_frame(pose: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """(distance, bearing) of ``goal`` (..., 2) seen from ``pose`` (..., 3)."""
    dx = goal[..., 0] - pose[..., 0]
    dy = goal[..., 1] - pose[..., 1]
    bearing = np.arctan2(dy, dx) - pose[..., 2]
    bearing = (bearing + np.pi) % (2 * np.pi) - np.pi
    return np.stack([np.hypot(dx, dy), bearing], axis=-1)


class GoalSampler:
    """The places that may be goals: within ``max_goal_distance`` of the start, not at it."""

    def __init__(self, places: dict[str, tuple[float, float, float]], start, cfg: NavConfig):
        names = sorted(places)
        pts = np.array([places[n][:2] for n in names], dtype=np.float64)
        d = np.hypot(pts[:, 0] - start[0], pts[:, 1] - start[1])
        keep = (d > 2.0 * cfg.goal_radius) & (d <= cfg.max_goal_distance)
        if not keep.any():
            raise sim.SimError(
                f"no place lies between {2 * cfg.goal_radius} m and "
                f"{cfg.max_goal_distance} m of the start: no goals to draw"
            )
        self.names = [n for n, k in zip(names, keep) if k]
        self.points = pts[keep]

    def draw(self, rng: np.random.Generator) -> tuple[str, np.ndarray]:
        i = int(rng.integers(len(self.names)))
        return self.names[i], self.points[i]


def observation(
    ranges: np.ndarray, range_max: float, pose: np.ndarray, goal: np.ndarray, max_distance: float
):
    """The flat observation: the ranges in [0, reach] (no return, inf, and no scan, NaN, read
    as the reach; closer than the sensor's minimum, -inf, as 0), then the goal's distance
    (clipped to ``max_distance``) and bearing."""
    r = np.nan_to_num(ranges, nan=range_max, posinf=range_max, neginf=0.0)
    r = np.clip(r, 0.0, range_max).astype(np.float32)
    g = goal_in_robot_frame(pose, goal)
    g[..., 0] = np.minimum(g[..., 0], max_distance)
    return np.concatenate([r, g.astype(np.float32)], axis=-1)


def reward(cfg: NavConfig, before: float, after: float, collided, reached):
    """Progress, minus the step's cost, with the collision penalty and the goal reward."""
    r = cfg.progress_reward * (before - after) - cfg.step_penalty
    r = r - cfg.collision_penalty * collided + cfg.goal_reward * reached
    return r




def spaces(gym_spaces, beams: int, range_max: float, cfg: NavConfig):
    """The observation and action spaces of one robot."""
    low = np.concatenate([np.zeros(beams), [0.0, -np.pi]]).astype(np.float32)
    high = np.concatenate([np.full(beams, range_max), [cfg.max_distance, np.pi]])
    obs = gym_spaces.Box(low, high.astype(np.float32), dtype=np.float32)
    act = gym_spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
    return obs, act


def command(cfg: NavConfig, action) -> np.ndarray:
    """``(v, w)`` of actions in [-1, 1]² (the last axis), clipped to the box first."""
    a = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
    if not np.isfinite(a).all():
        raise ValueError(f"action {action!r}: expected finite numbers in [-1, 1]")
    v = np.where(a[..., 0] >= 0, a[..., 0] * cfg.max_v, -a[..., 0] * cfg.min_v)
    return np.stack([v, a[..., 1] * cfg.max_w], axis=-1)
