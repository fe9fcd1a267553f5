"""A controller written in Python: a wall follower drives the maze robot with its laser.

Each tick the engine calls ``follow_right_wall`` with the robot's observation (its latest
scan, odometry and, for evaluation, its true pose) and drives the robot with the returned
``(v, w)``. The run is recorded for Rerun.

    python sim/python/examples/maze_controller.py [SECONDS] [OUT.rrd]
"""

import sys

import numpy as np

import sim

WALL = 0.6  # m kept to the wall on the right


def follow_right_wall(obs: sim.Observation) -> tuple[float, float]:
    scan = obs.robot.scan
    if scan is None:  # no scan yet
        return (0.0, 0.0)
    angles, ranges = scan.angles, np.minimum(scan.ranges, scan.range_max)
    front = ranges[np.abs(angles) < np.radians(15)].min()
    right = ranges[np.abs(angles + np.pi / 2) < np.radians(20)].min()
    if front < WALL + 0.2:
        return (0.05, 1.0)  # wall ahead: turn left on the spot
    # keep the right wall at WALL: steer towards it when far, away when near
    w = float(np.clip(1.5 * (WALL - right), -0.8, 0.8))
    return (0.5, w)


def main() -> None:
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0
    rrd = sys.argv[2] if len(sys.argv) > 2 else None
    s = sim.Simulation(
        "maze_run", duration=seconds, rrd=rrd, controllers={"scout": follow_right_wall}
    )
    summary = s.run()
    robot = summary["robots"][0]
    print(f"drove {robot['distance_m']:.1f} m in {seconds:.0f} s, collisions: {robot['collisions']}")


if __name__ == "__main__":
    main()
