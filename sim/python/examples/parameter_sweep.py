"""A parameter sweep: MCL's particle count against its accuracy on the hospital loop, over
three seeds, as a pandas DataFrame (a list of dicts without pandas).

    python sim/python/examples/parameter_sweep.py [SECONDS]
"""

import sys

import sim

PARTICLES = [200, 1000, 5000]
SEEDS = [0, 1, 2]


def sweep(seconds: float) -> list[dict]:
    rows = []
    for particles in PARTICLES:
        for seed in SEEDS:
            s = sim.Simulation(
                "hospital_loop",
                seed=seed,
                duration=seconds,
                set={"robots[0].localization[0].max_particles": particles},
            )
            summary = s.run()
            mcl = summary["robots"][0]["localization"]["mcl"]
            rows.append(
                {
                    "particles": particles,
                    "seed": seed,
                    "ate_m": mcl["ate_map_rmse_m"],
                    "tracked": mcl["tracked_fraction"],
                    "wall_s": summary["wall_time_s"],
                }
            )
    return rows


def main() -> None:
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0
    rows = sweep(seconds)
    try:
        import pandas as pd
    except ImportError:
        for r in rows:
            print(r)
        return
    df = pd.DataFrame(rows)
    print(df.groupby("particles")[["ate_m", "tracked", "wall_s"]].mean())


if __name__ == "__main__":
    main()
