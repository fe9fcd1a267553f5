#!/usr/bin/env python3
"""Generates the bundled maps (ROS map_server PGM + YAML) from the layouts described below.

    python3 assets/maps/generate.py          # regenerate every map
    python3 assets/maps/generate.py --check  # exit 1 if a committed file differs

Layouts are vector shapes in world metres (x right, y up, origin at the lower-left corner of the
image). A cell is occupied (0) when its centre lies inside a shape, free (254) inside the
building, unknown (205) outside. The generator checks that the free space is connected for a
robot of radius 0.35 m and that every named place / route point has clearance. Standard library
only; deterministic.
"""

import math
import random
import sys
from collections import deque
from pathlib import Path

HERE = Path(__file__).resolve().parent
RES = 0.05
FREE, OCC, UNKNOWN = 254, 0, 205


class Grid:
    def __init__(self, width_m, height_m):
        self.w = round(width_m / RES)
        self.h = round(height_m / RES)
        self.cells = bytearray([UNKNOWN]) * (self.w * self.h)  # row 0 = bottom

    def cell_range(self, x0, y0, x1, y1):
        c0 = max(0, math.floor(x0 / RES - 0.5))
        r0 = max(0, math.floor(y0 / RES - 0.5))
        c1 = min(self.w, math.ceil(x1 / RES + 0.5))
        r1 = min(self.h, math.ceil(y1 / RES + 0.5))
        return c0, r0, c1, r1

    def fill(self, bounds, inside, value):
        c0, r0, c1, r1 = self.cell_range(*bounds)
        for r in range(r0, r1):
            y = (r + 0.5) * RES
            base = r * self.w
            for c in range(c0, c1):
                if inside((c + 0.5) * RES, y):
                    self.cells[base + c] = value

    def rect(self, x0, y0, x1, y1, value=OCC):
        self.fill((x0, y0, x1, y1), lambda x, y: x0 <= x <= x1 and y0 <= y <= y1, value)

    def wall(self, a, b, t=0.15):
        """A thick segment with square ends extended by t/2."""
        (ax, ay), (bx, by) = a, b
        length = math.hypot(bx - ax, by - ay)
        ux, uy = (bx - ax) / length, (by - ay) / length
        h = t / 2

        def inside(x, y):
            vx, vy = x - ax, y - ay
            along = vx * ux + vy * uy
            return -h <= along <= length + h and abs(-vx * uy + vy * ux) <= h

        self.fill((min(ax, bx) - h, min(ay, by) - h, max(ax, bx) + h, max(ay, by) + h), inside, OCC)

    def box(self, cx, cy, sx, sy, yaw=0.0):
        c, s = math.cos(yaw), math.sin(yaw)
        ex = abs(c * sx) / 2 + abs(s * sy) / 2
        ey = abs(s * sx) / 2 + abs(c * sy) / 2

        def inside(x, y):
            lx = c * (x - cx) + s * (y - cy)
            ly = -s * (x - cx) + c * (y - cy)
            return abs(lx) <= sx / 2 and abs(ly) <= sy / 2

        self.fill((cx - ex, cy - ey, cx + ex, cy + ey), inside, OCC)

    def disc(self, cx, cy, r):
        self.fill((cx - r, cy - r, cx + r, cy + r), lambda x, y: (x - cx) ** 2 + (y - cy) ** 2 <= r * r, OCC)

    def polygon(self, pts):
        xs, ys = [p[0] for p in pts], [p[1] for p in pts]

        def inside(x, y):
            odd = False
            for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1]):
                if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
                    odd = not odd
            return odd

        self.fill((min(xs), min(ys), max(xs), max(ys)), inside, OCC)

    # --- checks -------------------------------------------------------------------------------
    def clearance(self):
        """Chamfer distance (m) from every cell to the nearest occupied cell."""
        big = 1e9
        w, h = self.w, self.h
        d = [0.0 if v == OCC else big for v in self.cells]
        a, b = RES, RES * math.sqrt(2)
        for r in range(h):
            for c in range(w):
                i = r * w + c
                v = d[i]
                if v == 0.0:
                    continue
                if c > 0:
                    v = min(v, d[i - 1] + a)
                if r > 0:
                    v = min(v, d[i - w] + a)
                    if c > 0:
                        v = min(v, d[i - w - 1] + b)
                    if c < w - 1:
                        v = min(v, d[i - w + 1] + b)
                d[i] = v
        for r in range(h - 1, -1, -1):
            for c in range(w - 1, -1, -1):
                i = r * w + c
                v = d[i]
                if v == 0.0:
                    continue
                if c < w - 1:
                    v = min(v, d[i + 1] + a)
                if r < h - 1:
                    v = min(v, d[i + w] + a)
                    if c < w - 1:
                        v = min(v, d[i + w + 1] + b)
                    if c > 0:
                        v = min(v, d[i + w - 1] + b)
                d[i] = v
        return d

    def index(self, x, y):
        return math.floor(y / RES) * self.w + math.floor(x / RES)

    def reachable(self, dist, start, radius):
        """Cells a disc of `radius` can reach from `start` through free space."""
        ok = bytearray(len(self.cells))
        for i, v in enumerate(self.cells):
            ok[i] = v == FREE and dist[i] >= radius
        seen = bytearray(len(self.cells))
        s = self.index(*start)
        if not ok[s]:
            fail(f"start {start} is not free for a robot of radius {radius}")
        q = deque([s])
        seen[s] = 1
        w = self.w
        while q:
            i = q.popleft()
            c = i % w
            for j in (i - 1 if c > 0 else -1, i + 1 if c < w - 1 else -1, i - w, i + w):
                if 0 <= j < len(ok) and ok[j] and not seen[j]:
                    seen[j] = 1
                    q.append(j)
        return seen

    def pgm(self):
        out = bytearray(f"P5\n{self.w} {self.h}\n255\n".encode())
        for r in range(self.h - 1, -1, -1):
            out += self.cells[r * self.w:(r + 1) * self.w]
        return bytes(out)


def yaml_text(name):
    return (
        f"image: {name}.pgm\nresolution: {RES}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n"
    )


def fail(msg):
    print(f"error: {msg}", file=sys.stderr)
    sys.exit(1)


# ==== hospital ===================================================================================
# Interior [1, 63] × [1, 31]. Corridors along x: south y 6–8.5, main y 14.75–17.25, north
# y 23.5–26; cross corridors x 20–22.5 and 42–44.5 between them. Four rows of rooms.
W_OUT, W_IN, DOOR = 0.25, 0.15, 1.1


def hospital():
    g = Grid(64, 32)
    g.rect(1, 1, 63, 31, FREE)
    for a, b in [((1, 1), (63, 1)), ((1, 31), (63, 31)), ((1, 1), (1, 31)), ((63, 1), (63, 31))]:
        g.wall(a, b, W_OUT)
    rng = random.Random(20261122)
    places = {}
    rooms = []  # (name, x0, y0, x1, y1, door_x, door_side)

    def corridor_wall(y, x0, x1, doors):
        """A horizontal wall from x0 to x1 with door gaps centred at `doors`."""
        cuts = sorted(doors)
        x = x0
        for d in cuts:
            if d - DOOR / 2 > x:
                g.wall((x, y), (d - DOOR / 2, y), W_IN)
            x = d + DOOR / 2
        if x < x1:
            g.wall((x, y), (x1, y), W_IN)

    def row(y0, y1, door_y, splits, kinds):
        """Rooms between x splits; the door wall is at door_y (y0 or y1)."""
        doors = []
        for k, ((x0, x1), kind) in enumerate(zip(zip(splits, splits[1:]), kinds)):
            if kind is None:
                continue
            off = [0.3, 0.5, 0.75][k % 3]
            dx = x0 + 1.0 + off * (x1 - x0 - 2.0)
            doors.append(dx)
            rooms.append((kind, x0, y0, x1, y1, dx, door_y))
            if k > 0:
                g.wall((x0, y0), (x0, y1), W_IN)
        return doors

    # row A: y 1–6, doors onto the south corridor (wall y = 6)
    a_split = [1, 8, 15.5, 24, 31, 39.5, 47, 55, 63]
    da = row(1, 6, 6, a_split, ["ward"] * 8)
    corridor_wall(6, 1, 63, da)
    # row D: y 26–31, doors onto the north corridor (wall y = 26)
    d_split = [1, 9, 18, 27, 36, 45, 54, 63]
    dd = row(26, 31, 26, d_split, ["ward", "office", "ward", "ward", "office", "ward", "ward"])
    corridor_wall(26, 1, 63, dd)
    # rows B (y 8.5–14.75, doors up to the main corridor) and C (y 17.25–23.5, doors down)
    db = row(8.5, 14.75, 14.75, [1, 9, 20], ["pharmacy", "ward"])
    db += row(8.5, 14.75, 14.75, [22.5, 31, 42], ["ward", "office"])
    db += row(8.5, 14.75, 14.75, [44.5, 53, 63], ["ward", "ward"])
    dc = row(17.25, 23.5, 17.25, [44.5, 54, 63], ["office", "ward"])
    dc += row(17.25, 23.5, 17.25, [12, 20], ["office"])
    # walls of rows B and C: south side of B, north side of C, cross-corridor sides
    for y in (8.5, 23.5):
        for x0, x1 in ((1, 20), (22.5, 42), (44.5, 63)):
            g.wall((x0, y), (x1, y), W_IN)
    for x in (20, 22.5, 42, 44.5):
        g.wall((x, 8.5), (x, 14.75), W_IN)
        g.wall((x, 17.25), (x, 23.5), W_IN)
    corridor_wall(14.75, 1, 20, [d for d in db if d < 20])
    corridor_wall(14.75, 22.5, 42, [d for d in db if 22.5 < d < 42])
    corridor_wall(14.75, 44.5, 63, [d for d in db if d > 44.5])
    # row C west: reception hall (open to the corridor over 7 m) and an office; centre: lobby
    corridor_wall(17.25, 1, 20, [d for d in dc if d < 20] + [5.0, 6.0, 7.0, 8.0, 9.0, 10.0])
    g.wall((12, 17.25), (12, 23.5), W_IN)
    corridor_wall(17.25, 44.5, 63, [d for d in dc if d > 44.5])
    # elevator lobby: x 22.5–42, y 17.25–23.5, open to the main corridor between x 27 and 37
    corridor_wall(17.25, 22.5, 42, [27.5 + k for k in range(10)])
    g.box(29.0, 22.4, 2.2, 2.0)  # elevator shafts against the north wall
    g.box(35.5, 22.4, 2.2, 2.0)
    g.disc(26.0, 20.0, 0.3)  # lobby pillars
    g.disc(39.0, 20.5, 0.25)
    g.box(32.2, 19.6, 1.8, 0.5)  # bench
    places["elevator_lobby"] = (32.0, 18.7, math.pi / 2)
    # reception: L-shaped desk, waiting chairs
    g.polygon([(3.0, 20.0), (7.5, 20.0), (7.5, 20.7), (3.7, 20.7), (3.7, 22.6), (3.0, 22.6)])
    for k in range(4):
        g.box(9.0 + 0.7 * k, 22.8, 0.5, 0.5)
    places["reception"] = (6.0, 18.8, math.pi / 2)
    # pillars half in the main corridor walls (keeps ≥ 2.2 m clear)
    for x in (10.5, 33.0, 52.5):
        g.disc(x, 14.75, 0.3)
    for x in (18.5, 52.0):
        g.disc(x, 17.25, 0.25)

    # room furniture
    counts = {}
    for kind, x0, y0, x1, y1, dx, door_y in rooms:
        back = y0 if door_y == y1 else y1  # wall opposite the door
        inward = 1 if door_y == y0 else -1  # direction from the door into the room
        width = x1 - x0
        if kind == "ward":
            beds = max(1, min(4, int((width - 1.0) // 1.9)))
            beds = rng.choice([max(1, beds - 1), beds])
            for k in range(beds):
                bx = x0 + 1.2 + k * (width - 2.4) / max(1, beds - 1) if beds > 1 else x0 + width * 0.35
                by = back - inward * 1.25
                g.box(bx, by, 0.9, 2.0, rng.uniform(-0.15, 0.15))
            if rng.random() < 0.6:
                g.box(x1 - 0.5, (y0 + y1) / 2 + rng.uniform(-0.8, 0.8), 0.5, 0.8)  # locker
        elif kind == "office":
            g.box(x0 + width * 0.6, back - inward * 1.0, 1.6, 0.75, rng.uniform(-0.3, 0.3))
            g.box(x0 + 0.4, (y0 + y1) / 2, 0.5, 1.8)  # cabinet
        elif kind == "pharmacy":
            g.box(x0 + 0.3, (y0 + y1) / 2, 0.4, y1 - y0 - 1.0)  # shelves along the walls
            g.box((x0 + x1) / 2 - 0.5, y0 + 0.3, x1 - x0 - 2.0, 0.4)
            g.box(x0 + 3.5, (y0 + y1) / 2 - 0.3, 0.4, 2.5)  # island shelf
            places["pharmacy"] = (dx, door_y + inward * 1.3, math.pi / 2 * inward)
            continue
        counts[kind] = counts.get(kind, 0) + 1
        name = f"{kind}_{counts[kind]}"
        places[name] = (dx, door_y + inward * 1.3, math.pi / 2 * inward)

    # chargers in the corridor ends, corridor waypoints along the centrelines
    places.update({
        "charger_1": (2.2, 16.0, 0.0), "charger_2": (61.8, 16.0, math.pi),
        "charger_3": (2.2, 7.25, 0.0), "charger_4": (61.8, 24.75, math.pi),
        "corridor_main_w": (5.0, 16.0, 0.0), "corridor_main_c": (32.0, 16.0, 0.0),
        "corridor_main_e": (59.0, 16.0, math.pi), "corridor_main_cross_w": (21.25, 16.0, 0.0),
        "corridor_main_cross_e": (43.25, 16.0, 0.0),
        "corridor_south_w": (5.0, 7.25, 0.0), "corridor_south_c": (32.0, 7.25, 0.0),
        "corridor_south_e": (59.0, 7.25, math.pi), "corridor_south_cross_w": (21.25, 7.25, math.pi / 2),
        "corridor_south_cross_e": (43.25, 7.25, math.pi / 2),
        "corridor_north_w": (5.0, 24.75, 0.0), "corridor_north_c": (32.0, 24.75, 0.0),
        "corridor_north_e": (59.0, 24.75, math.pi), "corridor_north_cross_w": (21.25, 24.75, -math.pi / 2),
        "corridor_north_cross_e": (43.25, 24.75, -math.pi / 2),
    })
    return g, places, (32.0, 16.0)


# ==== maze =======================================================================================
# A 10 × 10 grid of 2 m cells (corridors 1.85 m between 0.15 m walls) inside a 20 × 20 m square.
MAZE_CELL = 2.0
# the route, cell by cell: a 20 m featureless corridor, a 16 m one, 90° turns, then a loop
# inside the symmetric 3 × 3-cell (6 × 6 m) room
MAZE_ROUTE = (
    [(x, 0) for x in range(10)] + [(9, y) for y in range(1, 9)] + [(x, 8) for x in (8, 7, 6)]
    + [(6, 7)] + [(x, 7) for x in (5, 4, 3, 2, 1)] + [(1, y) for y in (6, 5, 4)] + [(2, 4)]
    + [(3, 4), (3, 5), (4, 5), (5, 5), (5, 4), (5, 3), (4, 3), (3, 3), (3, 4)]
)
MAZE_ROOM = [(x, y) for x in (3, 4, 5) for y in (3, 4, 5)]
MAZE_BRANCHES = [((7, 8), (7, 9)), ((7, 9), (8, 9)), ((1, 7), (0, 7)), ((0, 7), (0, 8)),
                 ((0, 8), (0, 9)), ((1, 4), (1, 3)), ((1, 3), (1, 2)), ((1, 2), (2, 2)),
                 ((6, 7), (7, 7)), ((7, 7), (7, 6)), ((9, 8), (9, 9))]


def maze():
    g = Grid(20.5, 20.5)
    off = 0.25  # the maze's lower-left corner in the image
    g.rect(off, off, off + 20, off + 20, FREE)
    open_edges = set()
    for a, b in zip(MAZE_ROUTE, MAZE_ROUTE[1:]):
        open_edges.add(frozenset((a, b)))
    for a, b in MAZE_BRANCHES:
        open_edges.add(frozenset((a, b)))
    for a in MAZE_ROOM:
        for b in MAZE_ROOM:
            if abs(a[0] - b[0]) + abs(a[1] - b[1]) == 1:
                open_edges.add(frozenset((a, b)))
    used = {c for e in open_edges for c in e}
    for cx in range(10):
        for cy in range(10):
            x0, y0 = off + cx * MAZE_CELL, off + cy * MAZE_CELL
            if (cx, cy) not in used:
                # cells off every passage are solid
                g.rect(x0, y0, x0 + MAZE_CELL, y0 + MAZE_CELL, OCC)
                continue
            # east and north edges of every cell, plus the outer south/west edges
            if cx == 9 or frozenset(((cx, cy), (cx + 1, cy))) not in open_edges:
                g.wall((x0 + 2, y0), (x0 + 2, y0 + 2))
            if cy == 9 or frozenset(((cx, cy), (cx, cy + 1))) not in open_edges:
                g.wall((x0, y0 + 2), (x0 + 2, y0 + 2))
            if cx == 0:
                g.wall((x0, y0), (x0, y0 + 2))
            if cy == 0:
                g.wall((x0, y0), (x0 + 2, y0))
    centre = lambda c: (off + (c[0] + 0.5) * MAZE_CELL, off + (c[1] + 0.5) * MAZE_CELL)
    pts = []
    for a, b in zip(MAZE_ROUTE, MAZE_ROUTE[1:]):
        (ax, ay), (bx, by) = centre(a), centre(b)
        n = 4  # 2 m / 4 = 0.5 m spacing
        pts += [(ax + (bx - ax) * k / n, ay + (by - ay) * k / n) for k in range(n)]
    pts.append(centre(MAZE_ROUTE[-1]))
    return g, pts, centre(MAZE_ROUTE[0])


# ==== output =====================================================================================
def check_clear(dist, g, name, x, y, need):
    d = dist[g.index(x, y)]
    if d < need:
        fail(f"{name} at ({x:.2f}, {y:.2f}) has {d:.2f} m clearance, needs {need}")


def write_or_check(path, data, check, changed):
    if check:
        if not path.exists() or path.read_bytes() != data:
            changed.append(path)
    else:
        path.write_bytes(data)


def main():
    check = "--check" in sys.argv[1:]
    changed = []

    g, places, start = hospital()
    dist = g.clearance()
    reach = g.reachable(dist, start, 0.35)
    for name, (x, y, _) in places.items():
        check_clear(dist, g, name, x, y, 0.6)
        if not reach[g.index(x, y)]:
            fail(f"place {name} ({x}, {y}) is not reachable by a 0.35 m robot")
    d = HERE / "hospital"
    write_or_check(d / "hospital.pgm", g.pgm(), check, changed)
    write_or_check(d / "hospital.yaml", yaml_text("hospital").encode(), check, changed)
    lines = ["# Named places of the hospital map: pose = [x, y, yaw] (m, m, rad). Generated by",
             "# assets/maps/generate.py; every place has >= 0.6 m clearance and is reachable.", ""]
    for name in sorted(places):
        x, y, yaw = places[name]
        kind = name.rstrip("0123456789_").rsplit("_", 1)[0] if name[-1].isdigit() else name.split("_")[0]
        lines += [f"[places.{name}]", f"pose = [{x:.3f}, {y:.3f}, {yaw:.4f}]", f'kind = "{kind}"', ""]
    # fire doors across the two cross corridors, between the main and the south corridor: open
    # in the map, closed by scenario events (a closed one forces robots round by the other)
    doors = {"fire_door_w": ((19.9, 11.6), (22.6, 11.6)), "fire_door_e": ((41.9, 11.6), (44.6, 11.6))}
    lines += ["# Doors: wall segments a scenario event can close (open in the map image).", ""]
    for name in sorted(doors):
        (x0, y0), (x1, y1) = doors[name]
        lines += [f"[doors.{name}]", f"from = [{x0:.3f}, {y0:.3f}]", f"to = [{x1:.3f}, {y1:.3f}]",
                  "thickness = 0.15", ""]
    write_or_check(d / "places.toml", "\n".join(lines).encode(), check, changed)
    print(f"hospital: {g.w} x {g.h} cells, {len(places)} places, all reachable")

    g, route, start = maze()
    dist = g.clearance()
    reach = g.reachable(dist, start, 0.35)
    for i, (x, y) in enumerate(route):
        check_clear(dist, g, f"route point {i}", x, y, 0.5)
        if not reach[g.index(x, y)]:
            fail(f"route point {i} is not reachable")
    for i, ((ax, ay), (bx, by)) in enumerate(zip(route, route[1:])):
        for k in range(11):
            check_clear(dist, g, f"route segment {i}", ax + (bx - ax) * k / 10, ay + (by - ay) * k / 10, 0.4)
    d = HERE / "maze"
    write_or_check(d / "maze.pgm", g.pgm(), check, changed)
    write_or_check(d / "maze.yaml", yaml_text("maze").encode(), check, changed)
    text = ["# The maze route: waypoints [x, y] (m), 0.5 m apart along the corridor centrelines.",
            "# Generated by assets/maps/generate.py.", "points = ["]
    text += [f"  [{x:.3f}, {y:.3f}]," for x, y in route] + ["]", ""]
    write_or_check(d / "route.toml", "\n".join(text).encode(), check, changed)
    print(f"maze: {g.w} x {g.h} cells, route of {len(route)} points")

    if changed:
        fail("out of date: " + ", ".join(str(p) for p in changed))


if __name__ == "__main__":
    main()
