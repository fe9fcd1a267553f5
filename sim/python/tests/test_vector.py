"""Many worlds at once: stacked observations, autoreset, determinism, bad input."""

import numpy as np
import pytest

import sim


def single_world_poses(seed, commands, steps, ticks=1):
    s = sim.Simulation("maze_run", seed=seed, threads=1)
    r = s.robot("scout")
    out = []
    for k in range(steps):
        r.drive(*commands[k])
        s.run_for(ticks * s.dt)
        out.append(r.pose)
    return np.array(out)


def test_world_i_follows_a_single_world_with_its_seed_whatever_n_and_threads():
    rng = np.random.default_rng(0)
    steps = 30
    cmds = np.stack([rng.uniform([0.0, -1.0], [0.8, 1.0], size=(steps, 2)) for _ in range(3)])
    want = [single_world_poses(7 + i, cmds[i], steps, ticks=2) for i in range(3)]
    for n, threads in [(3, 1), (3, 2), (5, 2)]:
        v = sim.VecSimulation("maze_run", n, seed=7, threads=threads)
        obs = v.reset()
        assert obs["reset"].all() and list(obs["seeds"]) == [7 + i for i in range(n)]
        poses = []
        for k in range(steps):
            c = np.zeros((n, 1, 2))
            c[:3, 0] = cmds[:, k]
            obs = v.step(c, ticks=2)
            poses.append(obs["poses"][:3, 0])
        got = np.stack(poses, axis=1)
        for i in range(3):
            assert np.array_equal(got[i], want[i]), (n, threads, i)


def test_observations_are_stacked_arrays():
    v = sim.VecSimulation("hospital_patrol", 2, seed=1, threads=2, duration=5.0)
    assert v.num_worlds == 2 and v.robot_names == ["r1", "r2", "r3", "r4"]
    obs = v.reset()
    obs = v.step(np.zeros((2, 4, 2)), ticks=4)
    b = max(v.beams)
    assert obs["ranges"].shape == (2, 4, b) and obs["ranges"].dtype == np.float32
    assert obs["poses"].shape == (2, 4, 3) and obs["twists"].shape == (2, 4, 2)
    assert obs["collisions"].shape == (2, 4) and obs["collisions"].dtype == np.int64
    assert obs["time"] == pytest.approx([0.2, 0.2])
    assert not obs["done"].any() and not obs["reset"].any()
    assert np.isfinite(obs["ranges"]).any()


def test_finished_worlds_restart_at_the_next_step_with_the_next_seed():
    n = 2
    v = sim.VecSimulation("maze_run", n, seed=10, threads=1, duration=0.5)
    v.reset()
    stop = np.zeros((n, 1, 2))
    for _ in range(9):
        obs = v.step(stop)
        assert not obs["done"].any()
    obs = v.step(stop)  # the tenth tick ends the 0.5 s episode
    assert obs["done"].all() and obs["time"] == pytest.approx([0.5, 0.5])
    obs = v.step(np.full((n, 1, 2), 5.0))  # ignored: the worlds restart
    assert obs["reset"].all() and not obs["done"].any()
    assert obs["time"] == pytest.approx([0.0, 0.0])
    # episode 1 of world i: seed + i + 1 * n
    assert list(obs["seeds"]) == [12, 13] and v.episodes == [1, 1]
    # the caller ends world 0's episode: it restarts, world 1 steps on
    obs = v.step(stop, end=[True, False])
    assert list(obs["reset"]) == [True, False] and list(obs["seeds"]) == [14, 13]


def test_bad_commands_are_clear_errors():
    v = sim.VecSimulation("maze_run", 2, threads=1)
    v.reset()
    with pytest.raises(ValueError, match=r"shape \(2, 1, 2\).*got \[2, 2\]|got \(2, 2\)|dimensions"):
        v.step(np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"shape \(2, 1, 2\)"):
        v.step(np.zeros((3, 1, 2)))
    c = np.zeros((2, 1, 2))
    c[1, 0, 0] = np.nan
    with pytest.raises(sim.SimError, match="world 1: .*finite"):
        v.step(c)
    with pytest.raises(ValueError, match="end"):
        v.step(np.zeros((2, 1, 2)), end=[True])
    with pytest.raises(TypeError, match="unknown option `rrd`"):
        sim.VecSimulation("maze_run", 2, rrd="x.rrd")
    with pytest.raises(ValueError, match="num_worlds"):
        sim.VecSimulation("maze_run", 0)
    with pytest.raises(sim.ScenarioError):
        sim.VecSimulation("no_such_scenario", 2)
    # float32 commands are accepted as float64
    v.step(np.zeros((2, 1, 2), dtype=np.float32))
