#!/usr/bin/env bash
# Writes libFuzzer dictionaries (tests/fuzz/dicts/<target>.dict) for the scenario and override
# targets: every key name the scenario structs declare (serde fields and renames), and values
# whose size or kind reaches the checks (huge, tiny, negative and non-finite numbers). With
# them, mutation inserts whole keys, so a generated scenario gets past the TOML parse with a
# key the resolver knows, e.g. a look-ahead of 1e9 m or a looping route.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
mkdir -p "$here/dicts"
keys=$(grep -rhoE '^\s+pub [a-z_0-9]+:|rename = "[a-z_0-9]+"' "$repo/sim/src/scenario" |
    sed -E 's/^\s+pub ([a-z_0-9]+):/\1/; s/rename = "([a-z_0-9]+)"/\1/' | sort -u)
# the format's tables, as headers on lines of their own (from the bundled scenarios and the
# format's documentation), so mutation can add a whole section
tables=$({
    grep -ohE '^\[\[?[a-z_.]+\]\]?' "$repo"/assets/scenarios/*.toml "$repo/sim/docs/scenario-format.md"
    # shellcheck disable=SC2016 # the backticks are the Markdown's, not a command
    grep -ohE '`\[\[?[a-z_.]+\]\]?`' "$repo/sim/docs/scenario-format.md" | tr -d '`'
} | grep -v '^\[table\]$' | sort -u)
values=(1e9 1e300 -1e300 1e-300 0.0 -0.0 -1 nan inf -inf true false 4294967296 '[]' '{}'
    '[[0.0, 0.0]]' '"waypoints"' '"go"' '"mcl"' '"wander"')
{
    for k in $keys; do printf '"%s"\n"%s = "\n' "$k" "$k"; done
    for t in $tables; do printf '"\\x0A%s\\x0A"\n' "$t"; done
    for v in "${values[@]}"; do printf '"%s"\n' "${v//\"/\\\"}"; done
} >"$here/dicts/scenario.dict"
{
    for k in $keys; do printf '"%s"\n".%s"\n' "$k" "$k"; done
    printf '"%s"\n' '[0]' '[name=r1]' '=' 'robots.0.' '.0.'
    for v in "${values[@]}"; do printf '"%s"\n' "${v//\"/\\\"}"; done
} >"$here/dicts/overrides.dict"
wc -l "$here"/dicts/*.dict
