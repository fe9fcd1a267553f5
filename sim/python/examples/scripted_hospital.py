"""A scripted hospital: the bundled delivery scenario (four robots with MCL, each with a queue
of deliveries) driven by a script that watches the robots between ticks and reacts:

- when r1 reaches the pharmacy, the west fire door closes and r2 is also sent to ward 3;
- once r3's MCL has converged, r3 is kidnapped to the north corridor (will MCL find it?);
- the run stops when every robot has done its tasks.

The Python twin of ``sim/examples/scripted_hospital.rs``.

    python sim/python/examples/scripted_hospital.py [MAX_SECONDS]
"""

import math
import sys

import sim


def run(max_seconds: float) -> dict:
    s = sim.Simulation("hospital_delivery", duration=max_seconds)
    pharmacy = s.places["pharmacy"]
    report = {"door_closed_at": None, "kidnapped_at": None, "all_done": False}
    while not s.is_over:
        # look at the world every half second of simulated time
        s.run_for(0.5)
        now = s.time
        r1 = s.robot("r1")
        if report["door_closed_at"] is None and math.dist(r1.pose[:2], pharmacy[:2]) < 1.0:
            s.set_door("fire_door_w", False)
            s.robot("r2").go_to("ward_3")
            report["door_closed_at"] = now
        r3 = s.robot("r3")
        if report["kidnapped_at"] is None and r3.localizer("mcl").converged_after is not None:
            r3.teleport(s.places["corridor_north_w"])
            report["kidnapped_at"] = now
        if all(r.navigation is None or r.navigation["finished"] for r in s.robots):
            report["all_done"] = True
            break
    r3 = s.robot("r3")
    estimate = r3.localizer("mcl").pose
    report["r3_error_m"] = math.dist(estimate[:2], r3.pose[:2]) if estimate else None
    report["seconds"] = s.time
    s.finish()
    report["log"] = s.log
    return report


def main() -> None:
    max_seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 900.0
    r = run(max_seconds)
    for t, robot, what in r["log"]:
        print(f"{t:7.2f} s  {robot:3} {what}")
    print(
        f"door closed at {r['door_closed_at']} s, r3 kidnapped at {r['kidnapped_at']} s, "
        f"r3's MCL error at the end {r['r3_error_m']} m"
    )
    done = "every delivery done" if r["all_done"] else "stopped before every delivery was done"
    print(f"{done} after {r['seconds']:.1f} s")


if __name__ == "__main__":
    main()
