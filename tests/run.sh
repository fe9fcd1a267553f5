#!/usr/bin/env bash
# Runs every test of the workspace, in release mode, then the Python package's tests, then a
# sharded batch on a one-node Slurm cluster, then a short fuzzing pass over every reader of user
# files.
#
# The recording checks use the real Rerun 0.36.3 tools (`rerun rrd verify`, `rerun rrd stats` and
# the Python SDK's RrdReader), Foxglove's Python MCAP readers (mcap, mcap-ros2-support) and evo
# (evo_ape, evo_rpe); this script installs them from PyPI into virtual environments once (under
# $SIM_CACHE, default ~/.cache/sim) and points the tests at them, requiring them
# (SIM_REQUIRE_TOOLS=1).
set -euo pipefail
cd "$(dirname "$0")/.."

cache="${SIM_CACHE:-$HOME/.cache/sim}"
venv="$cache/venv-rerun-0.36.3"
if ! "$venv/bin/rerun" --version 2>/dev/null | grep -q "0.36.3"; then
    echo "setting up rerun-sdk 0.36.3 in $venv"
    mkdir -p "$cache"
    rm -rf "$venv"
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --disable-pip-version-check "rerun-sdk==0.36.3"
    "$venv/bin/rerun" analytics disable >/dev/null 2>&1 || true
fi
# Foxglove's Python MCAP readers, for the ROS 2 replay checks (tests/check_mcap.py)
if ! "$venv/bin/python" -c "from importlib.metadata import version as v
assert (v('mcap'), v('mcap-ros2-support')) == ('1.6.0', '0.6.0')" 2>/dev/null; then
    "$venv/bin/pip" install --quiet --disable-pip-version-check \
        "mcap==1.6.0" "mcap-ros2-support==0.6.0"
fi
export SIM_RERUN_VENV="$venv"
# evo, to score our TUM trajectories with its own evo_ape / evo_rpe (tests/check_evo.py); a
# venv of its own so its numpy/matplotlib pins cannot move the rerun SDK's
evo_venv="$cache/venv-evo-1.38.1"
if ! "$evo_venv/bin/python" -c "from importlib.metadata import version as v
assert v('evo') == '1.38.1'" 2>/dev/null; then
    echo "setting up evo 1.38.1 in $evo_venv"
    rm -rf "$evo_venv"
    python3 -m venv "$evo_venv"
    "$evo_venv/bin/pip" install --quiet --disable-pip-version-check "evo==1.38.1"
fi
export SIM_EVO_VENV="$evo_venv"
# Without their tools, plain `cargo test` skips the checks that need them; here every one runs,
# and a tool missing from its venv fails its tests.
export SIM_REQUIRE_TOOLS=1

cargo test --release --workspace

# The Python package (sim/python): `pip install` builds it with maturin (sharing the cargo
# target directory, so only the extension itself is compiled again) into a fresh virtual
# environment, then its pytest suite runs against the installed package.
py_venv="$(mktemp -d)/venv"
trap 'rm -rf "$(dirname "$py_venv")"' EXIT
python3 -m venv "$py_venv"
echo "building and installing the Python package into a fresh virtual environment"
"$py_venv/bin/pip" install --quiet --disable-pip-version-check "./sim/python[test,gym]"
(cd sim/python && "$py_venv/bin/python" -m pytest -p no:cacheprovider -q tests)

# Shards on a real scheduler: a one-node Slurm cluster made on the spot runs a batch as a job
# array of 4 shards (tests/slurm/shard.sbatch); the merged shards must equal the batch run whole.
SIM_BIN="${CARGO_TARGET_DIR:-target}/release/sim" tests/slurm/run.sh

# sim built without its .rrd recording (no `rrd` feature), as the fuzz crate below builds it:
# a run asked for a .rrd is refused by name (the one test, which must run)
no_rrd="$(cargo test -p sim --no-default-features --lib -- --exact \
    run::simulation::tests::builder::a_build_without_the_recording_refuses_a_rrd_by_name)"
echo "$no_rrd"
grep -q "test result: ok. 1 passed" <<<"$no_rrd" || { echo "the test without rrd did not run" >&2; exit 1; }

# Fuzzing (tests/fuzz, cargo fuzz on the stable toolchain): each reader of user files runs its
# seeds and every input that once failed, then 15 s of coverage-guided mutations. The long run
# is `tests/fuzz/run.sh 600` (sim/docs/reliability.md).
if ! cargo fuzz --version 2>/dev/null | grep -q "cargo-fuzz 0.13.2"; then
    echo "installing cargo-fuzz 0.13.2"
    cargo install --quiet --locked cargo-fuzz --version 0.13.2
fi
tests/fuzz/run.sh 15
