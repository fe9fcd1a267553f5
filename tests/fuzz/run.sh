#!/usr/bin/env bash
# Fuzzes every reader of user files with cargo fuzz (libFuzzer, coverage-guided, built on the
# stable toolchain with `--sanitizer none`).
#
#   tests/fuzz/run.sh [SECONDS] [TARGET...]       default: 600 s per target, every target
#   tests/fuzz/run.sh --runs N [TARGET...]        N inputs per target instead of a time
#
# Each target first runs every input of its seeds (tests/fuzz/seeds/<target>/: our own files
# and every input that once failed), then mutates its working corpus (tests/fuzz/corpus/
# <target>/, not committed) for SECONDS, with the dictionary tests/fuzz/dicts/<target>.dict where
# there is one (tests/fuzz/make_dicts.sh). A failure is a panic or abort, an input that takes
# more than 10 s, or an allocation over 2 GB (malloc_limit_mb); libFuzzer then writes the input
# to tests/fuzz/artifacts/<target>/ and this script exits non-zero. Fix the cause, then copy
# the input into seeds/<target>/ so it is replayed on every run.
#
# Needs: cargo install cargo-fuzz (0.13). CARGO_TARGET_DIR is honoured.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
if [ "${1:-}" = "--runs" ]; then
    [ -n "${2:-}" ] || { echo "usage: $0 --runs N [TARGET...]" >&2; exit 2; }
    limit=(-runs="$2")
    what="$2 inputs"
    shift 2
else
    limit=(-max_total_time="${1:-600}")
    what="${1:-600} s"
    shift || true
fi
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(scenario overrides map places roads carmen scans mcap batch)
fi
cd "$here/../.."
cargo fuzz build --sanitizer none --fuzz-dir tests/fuzz -O
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
for t in "${targets[@]}"; do
    mkdir -p "tests/fuzz/corpus/$t" "tests/fuzz/artifacts/$t"
    echo "== $t: its seeds, then $what of fuzzing"
    start=$(date +%s)
    dict=()
    [ ! -f "tests/fuzz/dicts/$t.dict" ] || dict=(-dict="tests/fuzz/dicts/$t.dict")
    status=0
    cargo fuzz run --sanitizer none --fuzz-dir tests/fuzz -O "$t" \
        "tests/fuzz/corpus/$t" "tests/fuzz/seeds/$t" -- \
        "${limit[@]}" "${dict[@]}" -timeout=10 -rss_limit_mb=4096 -malloc_limit_mb=2048 \
        -max_len=262144 -print_final_stats=1 \
        -artifact_prefix="tests/fuzz/artifacts/$t/" >"$log" 2>&1 || status=$?
    grep -E "^stat::(number_of_executed_units|peak_rss_mb)|^INFO: seed corpus|^#[0-9]+ +DONE" "$log" || true
    echo "$t: $(($(date +%s) - start)) s"
    if [ "$status" -ne 0 ] || [ -n "$(ls -A "tests/fuzz/artifacts/$t")" ]; then
        failed=1
        grep -v -e '^\s*\[' -e '^Output of' "$log" | cut -c1-300 | tail -40 >&2
        echo "$t: failed (exit $status); inputs in tests/fuzz/artifacts/$t" >&2
    fi
done
exit "${failed:-0}"
