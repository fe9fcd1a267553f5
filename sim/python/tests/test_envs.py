"""The learning environments, checked by Gymnasium's and PettingZoo's own checkers."""

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode
from pettingzoo.test import parallel_api_test

import sim
from sim.envs import HospitalNavEnv, HospitalNavVectorEnv, HospitalTeamNavEnv, NavConfig


def test_the_navigation_env_passes_gymnasiums_checker():
    check_env(HospitalNavEnv(), skip_render_check=True)


def test_an_episode_rewards_progress_and_ends_at_a_collision():
    env = HospitalNavEnv(NavConfig(max_steps=400))
    obs, info = env.reset(seed=3)
    assert obs.shape == (93,) and env.observation_space.contains(obs)
    assert obs[-2] == pytest.approx(info["distance"])
    total, steps, done = 0.0, 0, False
    while not done:
        # drive straight ahead: along the corridor, then into a wall
        obs, r, terminated, truncated, info = env.step(np.array([1.0, 0.0], dtype=np.float32))
        assert env.observation_space.contains(obs)
        total += r
        steps += 1
        done = terminated or truncated
    assert terminated and info["collided"], (steps, info)
    assert r < -5.0  # the collision penalty


def test_the_same_seed_gives_the_same_episode():
    def rollout(seed):
        env = HospitalNavEnv()
        obs, _ = env.reset(seed=seed)
        rng = np.random.default_rng(0)
        out = [obs]
        for _ in range(30):
            obs, *_ = env.step(rng.uniform(-1, 1, size=2).astype(np.float32))
            out.append(obs)
        return np.array(out)

    assert np.array_equal(rollout(5), rollout(5))
    assert not np.array_equal(rollout(5), rollout(6))


def test_the_vector_env_steps_every_copy_and_autoresets_next_step():
    n = 4
    env = HospitalNavVectorEnv(n, NavConfig(max_steps=20), threads=2)
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    obs, info = env.reset(seed=1)
    assert obs.shape == (n, 93) and env.observation_space.contains(obs)
    ended = np.zeros(n, dtype=bool)
    ever = np.zeros(n, dtype=bool)
    for _ in range(25):
        obs, r, term, trunc, info = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs)
        # an environment that ended at the last step restarts now: reward 0, not ended
        assert (r[ended] == 0).all() and not (term[ended] | trunc[ended]).any()
        ended = term | trunc
        ever |= ended
    # every copy ended (truncated after 20 steps at the latest)
    assert ever.all()
    env.close()


def test_the_vector_env_matches_the_seed_rules():
    a = HospitalNavVectorEnv(2, threads=1)
    b = HospitalNavVectorEnv(2, threads=2)
    oa, _ = a.reset(seed=9)
    ob, _ = b.reset(seed=9)
    assert np.array_equal(oa, ob)
    acts = np.array([[0.5, 0.2], [0.3, -0.4]], dtype=np.float32)
    with pytest.raises(ValueError, match=r"shape \(2, 2\)"):
        a.step(acts[0])
    for _ in range(10):
        ra = a.step(acts)
        rb = b.step(acts)
        assert np.array_equal(ra[0], rb[0]) and np.array_equal(ra[1], rb[1])


def test_the_team_env_passes_pettingzoos_parallel_api_test():
    parallel_api_test(HospitalTeamNavEnv(), num_cycles=200)


def test_the_team_env_refuses_a_missing_action():
    env = HospitalTeamNavEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="no action for agent `r2`"):
        env.step({"r1": [0.0, 0.0], "r3": [0.0, 0.0]})


def test_bad_actions_are_refused():
    env = HospitalNavEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="finite"):
        env.step(np.array([np.nan, 0.0]))
