"""A random policy on the vectorized navigation environment: how many environment steps per
second the engine delivers (needs the `gym` extra).

    python sim/python/examples/vector_rollout.py [NUM_ENVS] [STEPS] [THREADS]
"""

import sys
import time

import numpy as np

from sim.envs import HospitalNavVectorEnv


def rollout(num_envs: int, steps: int, threads: int) -> dict:
    env = HospitalNavVectorEnv(num_envs, threads=threads)
    obs, _ = env.reset(seed=0)
    rng = np.random.default_rng(0)
    episodes, returns, current = 0, [], np.zeros(num_envs)
    start = time.perf_counter()
    for _ in range(steps):
        actions = rng.uniform(-1, 1, size=(num_envs, 2)).astype(np.float32)
        obs, reward, terminated, truncated, _ = env.step(actions)
        current += reward
        ended = terminated | truncated
        episodes += int(ended.sum())
        returns.extend(current[ended])
        current[ended] = 0.0
    wall = time.perf_counter() - start
    return {
        "env_steps_per_s": num_envs * steps / wall,
        "sim_seconds_per_s": num_envs * steps * env.cfg.ticks_per_step * 0.05 / wall,
        "episodes": episodes,
        "mean_return": float(np.mean(returns)) if returns else float("nan"),
    }


def main() -> None:
    num_envs = int(sys.argv[1]) if len(sys.argv) > 1 else 64
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else 500
    threads = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    r = rollout(num_envs, steps, threads)
    print(
        f"{num_envs} envs x {steps} steps: {r['env_steps_per_s']:.0f} env steps/s "
        f"({r['sim_seconds_per_s']:.0f} simulated s per s), {r['episodes']} episodes, "
        f"mean return {r['mean_return']:.2f}"
    )


if __name__ == "__main__":
    main()
