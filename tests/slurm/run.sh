#!/usr/bin/env bash
# Runs a sharded `sim batch` on a real Slurm scheduler and checks that the merged shards equal
# the same batch run whole.
#
# It installs Slurm and MUNGE from the distribution's packages if they are missing, starts a
# one-node cluster on this machine (munged, slurmctld, slurmd; localhost only, on free ports,
# with every file in a temporary folder of its own), submits tests/slurm/shard.sbatch as a job
# array of SHARDS tasks, merges the shards with `sim batch-merge`, runs the batch unsharded and
# compares the two with compare.py (every row bit for bit apart from wall-clock fields). It
# stops what it started on exit, and first stops what an earlier run that was killed left
# running. Prints the wall time of each phase.
#
#   tests/slurm/run.sh                                  # 4 shards, seeds 0..8, 10 s each
#   SHARDS=2 SEEDS=4 SIM_BIN=target/release/sim tests/slurm/run.sh
#
# Needs root, or sudo, for apt-get and the daemons (slurmd runs the jobs as the calling user).
# Without SIM_BIN it builds the sim binary (cargo build --release, honouring CARGO_TARGET_DIR).
# KEEP=1 keeps the temporary folder (configuration, logs, outputs).
set -euo pipefail
# Paths given relative to where it was called from, made absolute before moving to the repo.
[ -z "${SIM_BIN:-}" ] || SIM_BIN=$(realpath -m "$SIM_BIN")
[ -z "${CARGO_TARGET_DIR:-}" ] || CARGO_TARGET_DIR=$(realpath -m "$CARGO_TARGET_DIR") # exported
[ ! -f "${SCENARIO:-}" ] || SCENARIO=$(realpath "$SCENARIO")
cd "$(dirname "$0")/../.."
repo=$PWD

# --- sizes and limits (override from the environment) ----------------------------------------
SHARDS=${SHARDS:-4}                     # array tasks
SEEDS=${SEEDS:-8}                       # seeds 0..SEEDS over all shards
DURATION=${DURATION:-10}                # simulated seconds per run
SCENARIO=${SCENARIO:-hospital_patrol}   # a bundled scenario with localizers: real metrics
CPUS_PER_TASK=${CPUS_PER_TASK:-1}       # each task's --cpus-per-task, and its sim --jobs
NODE_TIMEOUT=${NODE_TIMEOUT:-90}        # seconds for the node to become idle
JOB_TIMEOUT=${JOB_TIMEOUT:-3600}        # seconds for the array job to finish
KEEP=${KEEP:-0}                         # 1: keep the temporary folder

for v in SHARDS SEEDS CPUS_PER_TASK NODE_TIMEOUT JOB_TIMEOUT; do
    [[ ${!v} =~ ^[1-9][0-9]*$ ]] || { echo "slurm test: $v must be a number from 1" >&2; exit 2; }
done

# --- helpers ---------------------------------------------------------------------------------
die() { echo "slurm test: $*" >&2; exit 1; }
say() { echo "== $*"; }

# Privileged commands: as they are when root, through sudo otherwise.
if [ "$(id -u)" -eq 0 ]; then
    SUDO=()
elif command -v sudo >/dev/null; then
    SUDO=(sudo)
else
    die "needs root for apt-get and the Slurm daemons: run it as root or install sudo"
fi
as_root() { "${SUDO[@]}" "$@"; }

# Phase timing: phase NAME starts a phase (ending the one before); the table is printed on exit.
phases=()
times=()
phase_name=""
phase_t0=0
now_us() { echo "${EPOCHREALTIME/./}"; }
phase_end() {
    if [ -n "$phase_name" ]; then
        phases+=("$phase_name")
        times+=($(($(now_us) - phase_t0)))
        phase_name=""
    fi
}
phase() {
    phase_end
    phase_name=$1
    phase_t0=$(now_us)
    say "$1"
}
print_phases() {
    local i total=0 us
    echo "phase            wall time"
    for i in "${!phases[@]}"; do
        us=${times[$i]}
        total=$((total + us))
        printf '%-16s %5d.%d s\n' "${phases[$i]}" $((us / 1000000)) $((us % 1000000 / 100000))
    done
    printf '%-16s %5d.%d s\n' total $((total / 1000000)) $((total % 1000000 / 100000))
}

# The processes of the cluster in folder $1: the daemons, the job steps and the jobs all carry
# SIM_SLURM_CLUSTER=$1 in their environment (given at their start), which nothing else has.
cluster_pids() {
    as_root grep -lzsx "SIM_SLURM_CLUSTER=$1" /proc/[0-9]*/environ 2>/dev/null |
        cut -d/ -f3 || true
}

# Stops the cluster in folder $1: cancels its jobs, then TERM and, after 15 s, KILL to each of
# its processes by id.
stop_cluster() {
    local dir=$1 pids i
    # Jobs first, through Slurm (slurmstepd outlasts a TERM while its job runs), for 15 s at most.
    if [ -S "$dir/munge/munge.sock" ] && [ -f "$dir/slurm.conf" ]; then
        local conf=$dir/slurm.conf name
        name=$(basename "$dir")
        if SLURM_CONF=$conf timeout 10 scancel --quiet --name "$name" 2>/dev/null; then
            for i in $(seq 30); do
                [ -n "$(SLURM_CONF=$conf timeout 5 squeue -h --name "$name" 2>/dev/null)" ] ||
                    break
                sleep 0.5
            done
        fi
    fi
    pids=$(cluster_pids "$dir")
    [ -n "$pids" ] || return 0
    # shellcheck disable=SC2086 # one id per word
    as_root kill -TERM $pids 2>/dev/null || true
    for i in $(seq 30); do
        pids=$(cluster_pids "$dir")
        [ -n "$pids" ] || return 0
        sleep 0.5
    done
    echo "still running after 15 s, killed: ${pids//$'\n'/ }" >&2
    # shellcheck disable=SC2086
    as_root kill -KILL $pids 2>/dev/null || true
}

# A run's identity, if it is alive: its pid and start time (a reused pid is another process;
# a killed run may stay a zombie for a while).
owner_of() {
    local stat f
    stat=$(cat "/proc/$1/stat" 2>/dev/null) || return 0
    read -r -a f <<<"${stat##*) }"
    [ "${f[0]}" = Z ] || echo "$1 ${f[19]}"
}

show_logs() {
    local f
    for f in "$dir"/log/*.log; do
        [ -f "$f" ] || continue
        echo "--- $f (last 40 lines)" >&2
        as_root tail -n 40 "$f" >&2 || true
    done
}

# On exit, however it comes: stop the cluster and remove its folder (kept after a failure, or
# with KEEP=1, for its logs), then print the phases' times.
dir=""
policy=""
cleanup() {
    local rc=$?
    trap - EXIT
    [ -z "$policy" ] || as_root rm -f "$policy"
    if [ -n "$dir" ]; then
        phase "cluster stop"
        stop_cluster "$dir"
        if [ "$KEEP" = 1 ] || [ $rc -ne 0 ]; then
            echo "kept $dir (configuration, log/, work/)"
        else
            as_root rm -rf "$dir"
        fi
    fi
    phase_end
    [ ${#phases[@]} -eq 0 ] || print_phases
    exit $rc
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# --- install ---------------------------------------------------------------------------------
phase install
missing=()
for cmd in slurmctld:slurmctld slurmd:slurmd sbatch:slurm-client munged:munge \
    mungekey:munge python3:python3; do
    command -v "${cmd%%:*}" >/dev/null || missing+=("${cmd#*:}")
done
if [ ${#missing[@]} -gt 0 ]; then
    mapfile -t missing < <(printf '%s\n' "${missing[@]}" | sort -u)
    say "installing ${missing[*]}"
    # Without systemd, keep the packages from starting their daemons with the default
    # configuration: a policy-rc.d that refuses, only while installing, and only if none is there.
    if [ ! -d /run/systemd/system ] && [ ! -e /usr/sbin/policy-rc.d ]; then
        policy=/usr/sbin/policy-rc.d
        printf '#!/bin/sh\nexit 101\n' | as_root tee "$policy" >/dev/null
        as_root chmod 755 "$policy"
    fi
    as_root env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
        "${missing[@]}" >/dev/null
    [ -z "$policy" ] || as_root rm -f "$policy"
    policy=""
fi
slurmctld -V

# --- the sim binary --------------------------------------------------------------------------
if [ -z "${SIM_BIN:-}" ]; then
    phase build
    cargo build --release --bin sim
    SIM_BIN=${CARGO_TARGET_DIR:-target}/release/sim
fi
SIM_BIN=$(realpath -m "$SIM_BIN")
[ -x "$SIM_BIN" ] || die "no sim binary at $SIM_BIN"
export SIM_ASSETS="$repo/assets" # bundled scenarios, wherever the tasks run

# --- the cluster -----------------------------------------------------------------------------
phase "cluster start"
tmp=${TMPDIR:-/tmp}

# Clusters that earlier runs left running (killed before their trap ran): stop them and remove
# their folders, unless the run that made one is still going.
for old in "$tmp"/sim-slurm.*; do
    [ -d "$old" ] || continue
    read -r pid start 2>/dev/null <"$old/owner" || pid=""
    if [ -n "$pid" ] && [ "$(owner_of "$pid")" = "$pid $start" ]; then
        continue
    fi
    echo "removing what an earlier run left in $old (stopping its processes)"
    stop_cluster "$old"
    as_root rm -rf "$old"
done

# Root owns the folder: munged refuses a key or socket folder that another user could change.
dir=$(as_root mktemp -d "$tmp/sim-slurm.XXXXXX")
as_root chmod 755 "$dir"
owner_of $$ | as_root tee "$dir/owner" >/dev/null
as_root mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
as_root chmod 711 "$dir/munge" # clients reach the socket by its path
work=$dir/work
as_root install -d -o "$(id -u)" -g "$(id -g)" "$work"

# MUNGE: a key of its own, a socket in the folder.
as_root mungekey --create --keyfile="$dir/munge/munge.key"
as_root env SIM_SLURM_CLUSTER="$dir" munged \
    --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.sock" \
    --pid-file="$dir/munge/munged.pid" --seed-file="$dir/munge/munged.seed" \
    --log-file="$dir/log/munged.log"

# Two free TCP ports on localhost, for slurmctld and slurmd.
read -r ctld_port slurmd_port < <(python3 -c '
import socket
ss = [socket.socket() for _ in range(2)]
for s in ss:
    s.bind(("127.0.0.1", 0))
print(*(s.getsockname()[1] for s in ss))')

# This machine's CPUs, their layout and memory, as slurmd sees them (CPUs=2 Boards=1 ...
# RealMemory=24105); else the online CPUs and MemTotal.
hw=$(slurmd -C 2>/dev/null | sed -n 's/^NodeName=[^ ]* \(CPUs=.*RealMemory=[0-9]*\).*/\1/p')
[ -n "$hw" ] || hw="CPUs=$(getconf _NPROCESSORS_ONLN) RealMemory=$(($(
    sed -n 's/^MemTotal: *\([0-9]*\) kB/\1/p' /proc/meminfo) / 1024))"

# No cgroups (this may be a container): processes tracked by their parent ids, no task binding.
# MinJobAge=4 (finished jobs kept 4 s): sbatch --wait polls every 2 s instead of backing off
# to 32 s (its period grows while below half MinJobAge); batch_sched_delay=0 starts jobs at once.
as_root tee "$dir/slurm.conf" >/dev/null <<EOF
ClusterName=simtest
SlurmctldHost=localhost
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.sock
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
MailProg=/bin/true
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
InactiveLimit=0
KillWait=5
MinJobAge=4
NodeName=localhost NodeAddr=127.0.0.1 $hw State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$dir/slurm.conf # for sbatch, sinfo, scancel

as_root env SIM_SLURM_CLUSTER="$dir" slurmctld -f "$SLURM_CONF" ||
    { show_logs; die "slurmctld did not start"; }
as_root env SIM_SLURM_CLUSTER="$dir" slurmd -f "$SLURM_CONF" -N localhost ||
    { show_logs; die "slurmd did not start"; }

# Wait until the node is idle.
state=""
for _ in $(seq $((NODE_TIMEOUT * 2))); do
    state=$(sinfo -h -N -n localhost -o %t 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.5
done
if [ "$state" != idle ]; then
    show_logs
    die "the node is '${state:-unknown}', not idle, after ${NODE_TIMEOUT}s (logs above)"
fi
sinfo -N -o '%N %t %c %m %P'

# --- the array job ---------------------------------------------------------------------------
phase "array job"
name=$(basename "$dir") # scancel finds the job by it
if ! SIM_BIN="$SIM_BIN" SCENARIO="$SCENARIO" SEEDS="$SEEDS" DURATION="$DURATION" OUT="$work" \
    SIM_SLURM_CLUSTER="$dir" timeout "$JOB_TIMEOUT" sbatch --wait \
    --job-name="$name" --array="0-$((SHARDS - 1))" --cpus-per-task="$CPUS_PER_TASK" \
    --chdir="$work" --output="$work/slurm-%A_%a.out" tests/slurm/shard.sbatch; then
    for f in "$work"/slurm-*.out; do
        [ -f "$f" ] && { echo "--- $f (last 20 lines)" >&2; tail -n 20 "$f" >&2; }
    done
    show_logs
    die "the array job failed (task outputs and logs above)"
fi
ls -d "$work"/shard*

# --- merge -----------------------------------------------------------------------------------
phase merge
"$SIM_BIN" batch-merge "$work/merged" "$work"/shard*

# --- the same batch unsharded ----------------------------------------------------------------
phase unsharded
"$SIM_BIN" batch "$SCENARIO" --seeds "0..$SEEDS" --duration "$DURATION" --out "$work/whole"

# --- compare ---------------------------------------------------------------------------------
phase compare
python3 tests/slurm/compare.py "$work/merged" "$work/whole"
echo "slurm test: $SHARDS shards × $SEEDS seeds of $SCENARIO merged equal the whole batch"
