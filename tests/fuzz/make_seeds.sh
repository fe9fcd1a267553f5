#!/usr/bin/env bash
# Writes the fuzz targets' seed inputs (tests/fuzz/seeds/<target>/) from our own files: the
# bundled scenarios, maps, places and roads, and short runs' CARMEN, SCANS, MCAP and batch
# outputs. Run from anywhere with a built `sim` (SIM, default: target/release/sim).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
sim="${SIM:-$repo/target/release/sim}"
seeds="$here/seeds"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
for t in scenario overrides map places roads carmen scans mcap batch; do
    mkdir -p "$seeds/$t"
done

# scenarios: paths as the fuzz scratch folder sees the assets (its `assets` link)
for f in "$repo"/assets/scenarios/*.toml; do
    sed -e 's#"\.\./maps/#"assets/maps/#g' -e 's#"\.\./roads/#"assets/roads/#g' "$f" \
        >"$seeds/scenario/$(basename "$f")"
done
cat >"$seeds/scenario/room.toml" <<'EOF'
duration = 1.0
walls = [
  { from = [0.0, 0.0], to = [10.0, 0.0] },
  { from = [0.0, 10.0], to = [10.0, 10.0] },
  { from = [0.0, 0.0], to = [0.0, 10.0] },
  { from = [10.0, 0.0], to = [10.0, 10.0] },
]
boxes = [{ center = [5.0, 5.0], size = [1.0, 1.0] }]
[[people]]
name = "alice"
route = [[2.0, 2.0], [8.0, 2.0]]
[[robots]]
name = "r1"
start = [2.0, 8.0, 0.0]
behaviour = { type = "wander", speed = 0.5 }
[robots.sensors.laser]
[robots.sensors.encoder]
[robots.sensors.sonar]
[[robots.localization]]
type = "mcl"
[[robots.slam]]
type = "graph"
[[events]]
at = 0.5
type = "drive"
robot = "r1"
v = 0.2
w = 0.1
EOF

# small worlds that also run their first ticks: the room map with a robot on tasks, and the
# maze's waypoint robot with its localizer
cat >"$seeds/scenario/room_tasks.toml" <<'TOML'
duration = 2.0
[map]
file = "room.yaml"
places = "places.toml"
[[robots]]
name = "r1"
start = "dock"
[robots.sensors.laser]
[robots.sensors.encoder]
[[robots.localization]]
type = "mcl"
max_particles = 200
[[robots.tasks]]
type = "go"
name = "across"
to = [1.5, 0.5]
TOML
sed -e 's#"\.\./maps/#"assets/maps/#g' -e 's#^duration = 200.0#duration = 1.0#' \
    "$repo/assets/scenarios/maze_run.toml" >"$seeds/scenario/maze_short.toml"
# and every behaviour and the navigation settings written out (as the bundled scenarios have
# them, on worlds too large to run here), so that one mutation changes any of their values:
# a looping patrol, and a robot on tasks with its planner and follower settings
cat >"$seeds/scenario/room_patrol.toml" <<'TOML'
duration = 2.0
walls = [
  { from = [0.0, 0.0], to = [6.0, 0.0] },
  { from = [0.0, 6.0], to = [6.0, 6.0] },
  { from = [0.0, 0.0], to = [0.0, 6.0] },
  { from = [6.0, 0.0], to = [6.0, 6.0] },
]
[[robots]]
name = "r1"
start = [2.0, 2.0, 0.0]
behaviour = { type = "waypoints", points = [[4.0, 2.0], [4.0, 4.0], [2.0, 4.0]], loop = true, speed = 0.5, tolerance = 0.3 }
[robots.sensors.laser]
[robots.sensors.encoder]
TOML
cat >"$seeds/scenario/room_navigation.toml" <<'TOML'
duration = 2.0
walls = [
  { from = [0.0, 0.0], to = [6.0, 0.0] },
  { from = [0.0, 6.0], to = [6.0, 6.0] },
  { from = [0.0, 0.0], to = [0.0, 6.0] },
  { from = [6.0, 0.0], to = [6.0, 6.0] },
]
boxes = [{ center = [3.0, 3.0], size = [1.0, 1.0] }]
[[robots]]
name = "r1"
start = [1.0, 1.0, 0.0]
[robots.sensors.laser]
[robots.sensors.encoder]
[robots.navigation]
speed = 0.5
max_accel = 0.5
max_yaw_rate = 1.0
tolerance = 0.2
lookahead = 0.6
safety_margin = 0.05
inflation_radius = 0.5
cost_weight = 1.0
stop_distance = 0.8
wait_time = 2.0
priority = 1
[[robots.tasks]]
type = "go"
name = "corner"
to = [5.0, 5.0]
TOML

# overrides, one per line
printf '%s\n' 'robots.0.sensors.laser.rate=5' 'duration=2' \
    'robots.0.localization.0.max_particles=500' >"$seeds/overrides/sets.txt"
printf '%s\n' 'robots[0].start=[0.5, 0.5, 0.0]' 'map.places="places.toml"' \
    'robots.0.behaviour={ type = "wander", speed = 0.3 }' >"$seeds/overrides/tables.txt"

# maps: YAML, a line ---, the image
{ cat "$repo/assets/maps/maze/maze.yaml"; printf '\n---\n'; cat "$repo/assets/maps/maze/maze.pgm"; } \
    >"$seeds/map/maze"
{ printf 'image: map.pgm\nresolution: 0.1\norigin: [-1.0, -2.0, 0.5]\nnegate: 1\nmode: scale\n'
  printf '\n---\n'; printf 'P5\n4 3\n255\n'; printf '\x00\x40\x80\xff%.0s' 1 2 3; } \
    >"$seeds/map/tiny"

# places and roads
cp "$repo/assets/maps/hospital/places.toml" "$seeds/places/hospital.toml"
printf '[places.dock]\npose = [0.5, 0.5, 0.0]\n[doors.d1]\nfrom = [1.0, 0.1]\nto = [1.0, 0.9]\n' \
    >"$seeds/places/small.toml"
cp "$repo/assets/roads/park/park.gpx" "$repo/assets/roads/park/park.osm" "$seeds/roads/"

# a short run's CARMEN log, SCANS file and MCAP file
"$sim" run maze_run --duration 1 --no-rrd --quiet --carmen-out "$tmp/maze.log" \
    --mcap "$tmp/maze.mcap"
cp "$tmp/maze.log" "$seeds/carmen/maze.log"
cp "$tmp/maze.mcap" "$seeds/mcap/maze.mcap"
"$sim" scans maze_run --duration 1 --period 0.5 --out "$tmp/maze.scans" >/dev/null
cp "$tmp/maze.scans" "$seeds/scans/maze.scans"

# two shards of a batch: batch.json, ---, runs.jsonl; the shards apart by ===
for k in 0 1; do
    "$sim" batch maze_run --seeds 0..2 --duration 0.5 --shard "$k/2" --out "$tmp/s$k" \
        >/dev/null
done
{ cat "$tmp/s0/batch.json"; printf '\n---\n'; cat "$tmp/s0/runs.jsonl"; printf '\n===\n'
  cat "$tmp/s1/batch.json"; printf '\n---\n'; cat "$tmp/s1/runs.jsonl"; } >"$seeds/batch/maze"
du -sh "$seeds"/*
