#!/usr/bin/env bash
# Soak: long runs measured for peak memory and for memory growth, and checked for identical
# results when run again; then a large batch that partly fails and loses a shard.
#
# 1. hospital_delivery (four robots, six people, a fire door that closes) for DELIVERY_S
#    simulated seconds (default 3600; its tasks repeated to last, long_delivery.py), with the
#    .rrd and the MCAP replay, twice: peak memory
#    (/usr/bin/time -v), resident memory sampled every SAMPLE_S seconds of wall time (the table),
#    and the two runs' summaries (apart from wall-clock fields), event logs, trajectories (every
#    estimate) and MCAP files must be identical.
# 2. A swarm of SWARM robots (default 10 000) wandering with 180-beam lasers for SWARM_S
#    simulated seconds (default 60), through `sim bench swarm`: peak memory and the same table.
# 3. A batch of 200 runs of maze_run (100 parameter sets × 2 seeds; one set has a speed the
#    scenario refuses, so 2 runs fail) in 4 shards, the third killed (SIGKILL) once it has
#    written KILL_AFTER rows: the failures are reported (exit code 2), `--resume` finishes the
#    killed shard, `sim batch-merge` joins the four, and the result equals the batch run whole
#    (tests/slurm/compare.py: every row bit for bit apart from wall-clock fields).
#
#   SIM_BIN=target/release/sim tests/soak/run.sh            # about 4 minutes on 2 cores
#   DELIVERY_S=600 SWARM=1000 tests/soak/run.sh             # smaller
#   PARTS=23 tests/soak/run.sh                              # parts 2 and 3 only
#
# Without SIM_BIN it builds the sim binary (cargo build --release, honouring CARGO_TARGET_DIR).
# Linux only (/proc). Prints the tables and exits non-zero at the first check that fails.
set -euo pipefail
[ -z "${SIM_BIN:-}" ] || SIM_BIN=$(realpath -m "$SIM_BIN")
cd "$(dirname "$0")/../.."
repo=$PWD

DELIVERY_S=${DELIVERY_S:-3600}
SWARM=${SWARM:-10000}
SWARM_S=${SWARM_S:-60}
SAMPLE_S=${SAMPLE_S:-1}
KILL_AFTER=${KILL_AFTER:-10}
PARTS=${PARTS:-123}                     # which of the three parts to run

if [ -z "${SIM_BIN:-}" ]; then
    cargo build --release --bin sim --quiet
    SIM_BIN=$(realpath "${CARGO_TARGET_DIR:-target}/release/sim")
fi
export SIM_ASSETS="$repo/assets"
command -v /usr/bin/time >/dev/null || { echo "soak: needs /usr/bin/time (Debian: time)" >&2; exit 1; }
work=$(mktemp -d "${TMPDIR:-/tmp}/sim-soak.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "soak: $*" >&2; exit 1; }

# measured NAME CMD...: runs CMD under /usr/bin/time -v in $work/NAME, sampling the resident
# memory of its process every SAMPLE_S s into NAME.rss ("wall_s rss_kB" lines); prints the peak
# and a table of ten samples, and the growth from the first quarter of the run to its end.
measured() {
    local name=$1; shift
    mkdir -p "$work/$name"
    local t0=$EPOCHREALTIME
    (cd "$work/$name" && exec /usr/bin/time -v -o time.txt "$@" >out.txt 2>err.txt) &
    local timer=$! pid=""
    : >"$work/$name.rss"
    while kill -0 "$timer" 2>/dev/null; do
        [ -n "$pid" ] || pid=$(pgrep -P "$timer" | head -n1 || true)
        if [ -n "$pid" ] && [ -r "/proc/$pid/status" ]; then
            local kb
            kb=$(awk '/^VmRSS:/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
            [ -z "$kb" ] || echo "$(echo "$EPOCHREALTIME - $t0" | bc) $kb" >>"$work/$name.rss"
        fi
        sleep "$SAMPLE_S"
    done
    local rc=0
    wait "$timer" || rc=$?
    [ "$rc" -eq 0 ] || { cat "$work/$name/err.txt" >&2; fail "$name exited with $rc"; }
    local peak wall
    peak=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$work/$name/time.txt")
    wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$work/$name/time.txt")
    echo "$name: wall $wall, peak resident memory $((peak / 1024)) MB"
    awk -v n="$(wc -l <"$work/$name.rss")" '
        BEGIN { print "| wall s | resident MB |"; print "|---|---|" }
        { t[NR] = $1; m[NR] = $2 }
        END {
            if (n == 0) exit
            for (k = 1; k <= 10; k++) {
                i = int(k * n / 10); if (i < 1) i = 1
                printf "| %.1f | %.1f |\n", t[i], m[i] / 1024
            }
            q = int(n / 4); if (q < 1) q = 1
            printf "growth from %.1f s to the end: %+.1f MB (%+.1f %%)\n", t[q], (m[n] - m[q]) / 1024, 100 * (m[n] - m[q]) / m[q]
        }' "$work/$name.rss"
}

if [[ $PARTS == *1* ]]; then
echo "== 1. hospital_delivery, ${DELIVERY_S} s simulated, twice"
python3 tests/soak/long_delivery.py "$repo/assets/scenarios/hospital_delivery.toml" "$work/delivery.toml" \
    "$DELIVERY_S"
for k in 1 2; do
    measured "delivery$k" "$SIM_BIN" run "$work/delivery.toml" --quiet \
        --rrd run.rrd --mcap run.mcap --summary summary.json --log events.log \
        --trajectories traj --all-estimates
done
python3 - "$work/delivery1" "$work/delivery2" <<'EOF'
import filecmp, json, os, re, sys
a, b = sys.argv[1:]
wall = re.compile(r"(wall_time_s|real_time_factor|_ms|_us)$")

def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if not wall.search(k) and k != "timing"}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v

sa, sb = (strip(json.load(open(os.path.join(d, "summary.json")))) for d in (a, b))
assert sa == sb, "the summaries differ"
traj = [os.path.relpath(os.path.join(d, f), a)
        for d, _, fs in os.walk(os.path.join(a, "traj")) for f in fs]
assert traj, "no trajectory files"
for f in ["events.log", "run.mcap"] + traj:
    assert filecmp.cmp(os.path.join(a, f), os.path.join(b, f), shallow=False), f + " differs"
print(f"identical on rerun: the summary (wall-clock fields aside), events.log, run.mcap "
      f"and {len(traj)} trajectory files")
EOF

fi

if [[ $PARTS == *2* ]]; then
echo "== 2. a swarm of $SWARM robots, ${SWARM_S} s simulated"
measured swarm "$SIM_BIN" bench swarm --robots "$SWARM" --per-hospital 400 --beams 180 \
    --duration "$SWARM_S" --json
cat "$work/swarm/out.txt"

fi

if [[ $PARTS == *3* ]]; then
echo "== 3. a batch of 200 runs in 4 shards: 2 runs fail, one shard is killed and resumed"
speeds=$(LC_ALL=C seq -s, 0.30 0.01 1.28),-1
batch=(batch maze_run --seeds 0..2 --duration 10 --sweep "robots.0.behaviour.speed=$speeds" --jobs 1)
cd "$work"
for k in 0 1 3; do
    rc=0; "$SIM_BIN" "${batch[@]}" --shard "$k/4" --out "shard$k" --quiet 2>"shard$k.err" || rc=$?
    [ "$rc" -eq 0 ] || [ "$rc" -eq 2 ] || fail "shard $k exited with $rc"
done
"$SIM_BIN" "${batch[@]}" --shard 2/4 --out shard2 --quiet 2>/dev/null &
victim=$!
until [ "$({ wc -l <shard2/runs.jsonl; } 2>/dev/null || echo 0)" -ge "$KILL_AFTER" ]; do
    kill -0 "$victim" 2>/dev/null || fail "shard 2 ended before it was killed"
    sleep 0.01
done
kill -KILL "$victim"
wait "$victim" 2>/dev/null || true
kept=$(wc -l <shard2/runs.jsonl)
echo "shard 2 killed with $kept of 50 rows written"
if "$SIM_BIN" batch-merge merged shard0 shard1 shard2 shard3 --quiet 2>merge.err; then
    fail "batch-merge took a killed shard"
fi
grep -q -- "--resume" merge.err || fail "batch-merge does not say how to finish the shard: $(cat merge.err)"
rc=0; "$SIM_BIN" "${batch[@]}" --shard 2/4 --out shard2 --resume >/dev/null 2>resume.err || rc=$?
grep "resuming" resume.err
[ "$rc" -eq 0 ] || [ "$rc" -eq 2 ] || fail "the resumed shard exited with $rc"
rc=0; "$SIM_BIN" batch-merge merged shard0 shard1 shard2 shard3 --quiet 2>merge.err || rc=$?
[ "$rc" -eq 2 ] || fail "the merge should exit with 2 (two runs failed), not $rc: $(cat merge.err)"
rc=0; "$SIM_BIN" "${batch[@]}" --out whole --quiet 2>whole.err || rc=$?
[ "$rc" -eq 2 ] || fail "the whole batch should exit with 2 (two runs fail), not $rc"
grep -q "2 of 200 runs failed" whole.err || fail "the failures are not reported: $(cat whole.err)"
failed=$(grep -c '"status":"failed"' merged/runs.jsonl)
[ "$failed" -eq 2 ] || fail "$failed failed rows in the merge, expected 2"
python3 "$repo/tests/slurm/compare.py" merged whole
fi
echo "soak: all checks passed"
