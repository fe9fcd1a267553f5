"""range_libc on our hospital map, for the ray-casting comparison of sim/docs/benchmarks.md,
"Against range_libc".

range_libc ([Walsh 2018]: Walsh & Karaman, "CDDT: Fast Approximate 2D Ray Casting for Accelerated
Localization", ICRA 2018) is the best C++ grid ray caster we know. This times it on the same
machine, map and kind of queries as `cargo bench -p systems --bench raycast`, so the two can be
compared on one day's hardware:

    python3 -m venv /tmp/rlc && /tmp/rlc/bin/pip install "cython<3" numpy setuptools wheel
    /tmp/rlc/bin/pip install --no-build-isolation pyrangelibc-danieldugas==0.0.2
    /tmp/rlc/bin/python systems/benches/compare_range_libc.py [--lut]

(the package builds range_libc from source with -O3 -march=native -ffast-math). Queries: 4096
random free poses with random headings, 20 m rays (`calc_range_many`); whole scans from 256 of
those poses, beam after beam (`calc_range_many` over each pose's beams in angle order: this
build's `calc_range_repeat_angles` is compiled out): 1081 beams over 270° to 20 m, 180 beams over 180° to
8 m and to 20 m. One thread; each figure is the median of 15 timings of at least 50 ms each, in
millions of rays per second. `--lut` also builds the giant lookup table (several minutes, hundreds of MB).
"""

import sys
import time
from pathlib import Path

import numpy as np
import range_libc

ROOT = Path(__file__).resolve().parents[2]


def load_hospital():
    """The hospital PGM as a bool array [row, col] with row 0 at the top, and the resolution."""
    yaml = (ROOT / "assets/maps/hospital/hospital.yaml").read_text()
    meta = dict(
        line.split(":", 1) for line in yaml.splitlines() if ":" in line and not line.startswith("#")
    )
    res = float(meta["resolution"])
    occ_thresh = float(meta["occupied_thresh"])
    data = (ROOT / "assets/maps/hospital" / meta["image"].strip()).read_bytes()
    # binary PGM: magic, width, height, maxval, then the pixels
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end : end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    assert fields[0] == b"P5", "expected a binary PGM"
    w, h, maxval = (int(f) for f in fields[1:])
    px = np.frombuffer(data, dtype=np.uint8, count=w * h, offset=pos + 1).reshape(h, w)
    # map_server, negate 0: occupancy = (255 - p) / 255
    occupied = (maxval - px.astype(np.float64)) / maxval > occ_thresh
    return occupied, res


def median_rate(fn, rays, reps=15, min_s=0.05):
    """Median over `reps` timings, each of as many calls as take `min_s` (short timings are
    at the mercy of the shared machine)."""
    fn()  # warm up
    t0 = time.perf_counter()
    fn()
    calls = max(1, int(min_s / max(time.perf_counter() - t0, 1e-9)))
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        times.append((time.perf_counter() - t0) / calls)
    return rays / float(np.median(times)) / 1e6


def main():
    occupied, res = load_hospital()
    h, w = occupied.shape
    omap = range_libc.PyOMap(np.ascontiguousarray(occupied))
    rng = np.random.default_rng(1)
    free = np.argwhere(~occupied)
    pick = free[rng.integers(0, len(free), 4096)]
    # (x, y, heading) in cells: x along columns, y along rows as range_libc indexes its grid
    poses = np.empty((4096, 3), dtype=np.float32)
    poses[:, 0] = pick[:, 1] + rng.random(4096)
    poses[:, 1] = pick[:, 0] + rng.random(4096)
    poses[:, 2] = rng.uniform(-np.pi, np.pi, 4096)
    scan_poses = np.ascontiguousarray(poses[:256])
    print(f"hospital map {w} x {h} cells of {res} m, range_libc {range_libc.__file__}")

    def casters(max_px):
        yield "bresenham", range_libc.PyBresenhamsLine(omap, max_px)
        yield "ray marching", range_libc.PyRayMarching(omap, max_px)
        t0 = time.perf_counter()
        cddt = range_libc.PyCDDTCast(omap, max_px, 108)
        built = time.perf_counter() - t0
        yield f"cddt (built in {built:.1f} s)", cddt
        t0 = time.perf_counter()
        pcddt = range_libc.PyCDDTCast(omap, max_px, 108)
        pcddt.prune()
        built = time.perf_counter() - t0
        yield f"pruned cddt (built in {built:.1f} s)", pcddt
        if "--lut" in sys.argv:
            t0 = time.perf_counter()
            lut = range_libc.PyGiantLUTCast(omap, max_px, 108)
            built = time.perf_counter() - t0
            yield f"giant lut (built in {built:.1f} s)", lut

    rows = []
    max20 = 20.0 / res
    out = np.empty(4096, dtype=np.float32)
    for name, c in casters(max20):
        rows.append(
            (
                "single random rays, 20 m",
                name,
                median_rate(lambda: c.calc_range_many(poses, out), 4096),
            )
        )
        # a check that every method answers the same queries: their mean ranges agree
        hits = out[out < max20]
        print(f"{name}: random rays' mean range {hits.mean() * res:.2f} m, {len(hits)} hits")
    for beams, fov, rng_m in [(1081, 270.0, 20.0), (180, 180.0, 8.0), (180, 180.0, 20.0)]:
        angles = np.linspace(-np.radians(fov) / 2, np.radians(fov) / 2, beams).astype(np.float32)
        # every beam of a scan in angle order, scan after scan
        ins = np.repeat(scan_poses, beams, axis=0)
        ins[:, 2] += np.tile(angles, 256)
        outs = np.empty(256 * beams, dtype=np.float32)
        for name, c in casters(rng_m / res):
            rate = median_rate(lambda: c.calc_range_many(ins, outs), 256 * beams)
            rows.append((f"{beams}-beam scans, {fov:.0f}°, {rng_m:.0f} m", name, rate))
    print("| queries | range_libc method | M rays/s |")
    print("|---|---|---|")
    for q, name, rate in rows:
        print(f"| {q} | {name} | {rate:.1f} |")


if __name__ == "__main__":
    main()
