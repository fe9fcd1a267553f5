#!/usr/bin/env python3
"""Scores the simulator's TUM trajectories with evo's own command-line tools and compares the
results with the run summary's ATE/RPE figures.

Usage: check_evo.py TRAJECTORIES_DIR SUMMARY.json [--tolerance 1e-6]

TRAJECTORIES_DIR is what `sim run --trajectories DIR` writes: DIR/<robot>/<localizer>.tum and
DIR/<robot>/<localizer>.truth.tum. SUMMARY.json is `sim run --summary FILE`. For every pair:

  evo_ape tum TRUTH EST --align_origin                      -> rmse == ate_rmse_m
  evo_ape tum TRUTH EST                                     -> rmse == ate_map_rmse_m
  evo_rpe tum TRUTH EST --delta 1 --delta_unit f            -> mean == rpe_trans_m
  evo_rpe tum TRUTH EST --delta 1 --delta_unit f --pose_relation angle_rad
                                                            -> mean == rpe_rot_rad

each within the tolerance (absolute, metres or radians). The statistics are read from the
result files evo saves (--save_results), at full precision.

Needs: pip install evo==1.38.1 (tests/run.sh installs it). Prints one line per comparison and
"N passed, 0 failed"; exits non-zero on any difference or missing file.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

from evo.tools import file_interface

CHECKS = [
    ("evo_ape", ["--align_origin"], "rmse", "ate_rmse_m"),
    ("evo_ape", [], "rmse", "ate_map_rmse_m"),
    ("evo_rpe", ["--delta", "1", "--delta_unit", "f"], "mean", "rpe_trans_m"),
    (
        "evo_rpe",
        ["--delta", "1", "--delta_unit", "f", "--pose_relation", "angle_rad"],
        "mean",
        "rpe_rot_rad",
    ),
]


def evo_stat(tool, truth, est, flags, stat, workdir):
    """Runs one evo tool and returns the statistic from its saved results."""
    out = os.path.join(workdir, f"{tool}-{len(os.listdir(workdir))}.zip")
    exe = os.path.join(os.path.dirname(sys.executable), tool)
    cmd = [exe, "tum", truth, est, *flags, "--save_results", out, "--no_warnings"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stdout}\n{done.stderr}")
    return file_interface.load_res_file(out).stats[stat]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trajectories")
    parser.add_argument("summary")
    parser.add_argument("--tolerance", type=float, default=1e-6)
    args = parser.parse_args()
    with open(args.summary) as f:
        summary = json.load(f)
    passed, failed = 0, 0
    with tempfile.TemporaryDirectory() as workdir:
        for robot in summary["robots"]:
            for name, metrics in robot.get("localization", {}).items():
                base = os.path.join(args.trajectories, robot["name"], name)
                est, truth = base + ".tum", base + ".truth.tum"
                if not (os.path.exists(est) and os.path.exists(truth)):
                    print(f"FAIL {robot['name']}/{name}: {est} or {truth} is missing")
                    failed += 1
                    continue
                for tool, flags, stat, key in CHECKS:
                    ours = metrics.get(key)
                    if ours is None:
                        continue
                    theirs = evo_stat(tool, truth, est, flags, stat, workdir)
                    ok = abs(theirs - ours) <= args.tolerance
                    print(
                        f"{'ok  ' if ok else 'FAIL'} {robot['name']}/{name} {key}: "
                        f"ours {ours:.9f}, {tool} {' '.join(flags)} {stat} {theirs:.9f}"
                    )
                    passed += ok
                    failed += not ok
    print(f"{passed} passed, {failed} failed")
    sys.exit(1 if failed or not passed else 0)


if __name__ == "__main__":
    main()
