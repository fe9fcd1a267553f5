#!/usr/bin/env python3
"""Generates the park road map (OSM XML 0.6 + GPX 1.1) from the layout described below.

    python3 assets/roads/generate_park.py          # write park/park.osm, park/park.gpx, README.md
    python3 assets/roads/generate_park.py --check  # re-read the files, rebuild both graphs, print
                                                   # their statistics and the route lengths; exit 1
                                                   # if a file differs from what the generator
                                                   # writes, the graphs differ or a requirement fails

The park is a made-up layout in the spirit of the Vyšehrad park in Prague (a fortress park on a
rock: a main asphalt loop, an avenue across it, gravel paths, ramparts, gates and lookouts). It
is NOT traced from OpenStreetMap. It is designed in local metres (x east, y north, origin at the
reference point) and converted to latitude/longitude with the equirectangular projection

    x_east  = R cos(lat0) (lon - lon0) pi/180
    y_north = R (lat - lat0) pi/180,          R = 6378135 m

Roads are either polylines through their control points (`line`: every control point becomes a
node, straight pieces are split evenly so none is longer than 20 m) or smooth curves (`curve`: a
centripetal Catmull-Rom spline through the control points; only the named points are fixed nodes,
shape points are spread evenly, 8-15 m apart, between them). A named point used by several roads
is one shared node. Standard library only; deterministic.
"""

import heapq
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "park"
OSM_PATH = OUT / "park.osm"
GPX_PATH = OUT / "park.gpx"
README_PATH = HERE / "README.md"

LAT0, LON0 = 50.064500, 14.418000
R_EARTH = 6378135.0
COS0 = math.cos(math.radians(LAT0))

LINE_MAX = 20.0     # longest straight piece of a `line` road (the requirement is 25 m)
CURVE_STEP = 11.0   # target spacing of shape points on a `curve` road (8-15 m)

# --- layout (local metres) -------------------------------------------------------------------
# Named points: junctions, road ends and places the routes use. Order matters: it fixes the ids.
PLACES = {
    # main loop (Rampart Road), clockwise from the west
    "rampart_west": (-98.0, -2.0),
    "rampart_northwest": (-82.0, 38.0),
    "rampart_linden": (-65.0, 56.0),
    "rampart_north_west": (-44.0, 68.0),
    "rampart_north": (0.0, 76.0),
    "rampart_north_east": (46.0, 74.0),
    "rampart_northeast": (92.0, 50.0),
    "rampart_east": (112.0, 4.0),
    "rampart_southeast": (98.0, -46.0),
    "rampart_south_east": (46.0, -76.0),
    "rampart_south": (0.0, -86.0),
    "rampart_southwest": (-82.0, -46.0),
    # Basilica Avenue, west gate to east gate
    "west_gate": (-148.0, 4.0),
    "bastion_cross": (-126.0, 3.0),
    "avenue_west": (-50.0, 1.0),
    "avenue_steps": (-30.0, 2.0),
    "avenue_cross": (0.0, 4.0),
    "avenue_cemetery": (34.0, 3.0),
    "avenue_east": (50.0, 2.0),
    "east_gate": (146.0, 0.0),
    # Chapter Road, north gate to the casemates
    "north_gate": (0.0, 120.0),
    "chapter_north": (0.0, 42.0),
    "chapter_south": (0.0, -38.0),
    "casemate_fork": (0.0, -108.0),
    # the triangle junction in the south-east quarter (side 12 m)
    "triangle_north": (58.0, -26.0),
    "triangle_southwest": (52.0, -36.4),
    "triangle_southeast": (64.0, -36.4),
    # paths
    "linden_fork": (-52.0, 34.0),
    "vineyard_fork": (-44.0, -36.0),
    "rotunda": (-72.0, 112.0),
    "casemates": (-60.0, -116.0),
    "casemate_entrance": (-58.0, -96.0),
    "steps_fork": (27.0, -102.0),
    "south_steps": (32.0, -123.0),
    "orchard_fork": (102.0, 92.0),
    "orchard_lookout": (146.0, 116.0),
    # named mid-road point (degree 2): start of the short route
    "orchard_start": (54.0, -12.0),
}

# (name, highway, surface, width, kind, closed, points)
ROADS = [
    ("Rampart Road", "service", "asphalt", "5.0", "curve", True,
     ["rampart_west", "rampart_northwest", "rampart_linden", "rampart_north_west",
      "rampart_north", "rampart_north_east", "rampart_northeast", "rampart_east",
      "rampart_southeast", "rampart_south_east", "rampart_south", (-46.0, -74.0),
      "rampart_southwest"]),
    ("Basilica Avenue", "pedestrian", "asphalt", "4.0", "line", False,
     ["west_gate", "bastion_cross", "rampart_west", "avenue_west", "avenue_steps",
      "avenue_cross", "avenue_cemetery", "avenue_east", "rampart_east", "east_gate"]),
    ("Chapter Road", "pedestrian", "paving_stones", "3.5", "line", False,
     ["north_gate", "rampart_north", "chapter_north", "avenue_cross", "chapter_south",
      "rampart_south", "casemate_fork"]),
    ("Linden Path", "footway", "gravel", "3.0", "curve", False,
     ["avenue_west", (-58.0, 18.0), "linden_fork", (-58.0, 46.0), "rampart_linden"]),
    ("Cemetery Walk", "footway", "gravel", "3.0", "curve", False,
     ["linden_fork", (-26.0, 40.0), "chapter_north", (20.0, 44.0), (38.0, 36.0),
      "avenue_cemetery"]),
    ("Vineyard Path", "footway", "gravel", "3.0", "curve", False,
     ["rampart_southwest", (-64.0, -40.0), "vineyard_fork", (-22.0, -36.0), "chapter_south"]),
    ("Vineyard Steps", "path", "gravel", "2.5", "curve", False,
     ["avenue_steps", (-38.0, -16.0), "vineyard_fork"]),
    ("Orchard Path", "footway", "gravel", "3.0", "curve", False,
     ["avenue_east", "orchard_start", "triangle_north"]),
    ("Triangle North-West", "path", "gravel", "2.5", "line", False,
     ["triangle_north", "triangle_southwest"]),
    ("Triangle North-East", "path", "gravel", "2.5", "line", False,
     ["triangle_north", "triangle_southeast"]),
    ("Triangle South", "path", "gravel", "2.5", "line", False,
     ["triangle_southwest", "triangle_southeast"]),
    ("Well Path", "footway", "gravel", "3.0", "curve", False,
     ["triangle_southwest", (44.0, -56.0), "rampart_south_east"]),
    ("Bastion Path", "footway", "gravel", "3.0", "curve", False,
     ["triangle_southeast", (78.0, -40.0), "rampart_southeast"]),
    ("Bastion Walk", "path", "gravel", "3.0", "curve", False,
     ["rampart_northwest", (-116.0, 60.0), (-132.0, 34.0), "bastion_cross",
      (-134.0, -30.0), (-116.0, -64.0), (-96.0, -100.0), "casemates"]),
    ("Rotunda Path", "path", "gravel", "2.5", "curve", False,
     ["rampart_north_west", (-54.0, 92.0), "rotunda"]),
    ("Casemate Path", "path", "gravel", "3.0", "curve", False,
     ["casemates", "casemate_fork", "steps_fork", "rampart_south_east"]),
    ("Casemate Entrance", "path", "gravel", "2.5", "line", False,
     ["casemates", "casemate_entrance"]),
    ("South Steps", "path", "gravel", "2.5", "line", False,
     ["steps_fork", "south_steps"]),
    ("Orchard Lane", "service", "asphalt", "4.0", "curve", False,
     ["rampart_north_east", (72.0, 88.0), "orchard_fork", "orchard_lookout"]),
    ("Orchard Walk", "footway", "gravel", "3.0", "curve", False,
     ["orchard_fork", "rampart_northeast", (74.0, 26.0), "avenue_east"]),
]

# Area features (closed ways, not roads: the road importer must ignore them).
# A 40 m x 15 m building inside the loop, 6 m east of Chapter Road and ~10 m south of the
# Rampart Road's north arc (GPS multipath / shadowing along both roads).
BUILDING = [(6.0, 52.0), (46.0, 52.0), (46.0, 67.0), (6.0, 67.0)]
# A grove over the Casemate Path between the Chapter Road end and the loop, and the South Steps.
WOOD = [(6.0, -96.0), (30.0, -86.0), (42.0, -100.0), (40.0, -124.0), (12.0, -124.0)]
# Suggested electromagnetic-interference spot (compass): a circle at the avenue_east junction.
EM_SPOT = ((46.0, 6.0), 12.0)  # centre, radius

ROUTES = [
    # (key, title, start, toward, goal): the robot starts at `start` facing the next node towards
    # `toward` (a named point at the end of the road stretch it stands on).
    ("long", "long route", "west_gate", "bastion_cross", "orchard_lookout"),
    ("short", "short route", "orchard_start", "avenue_east", "rampart_south_east"),
    ("third", "third route", "north_gate", "rampart_north", "south_steps"),
]


# --- geometry --------------------------------------------------------------------------------
def to_latlon(x, y):
    lat = LAT0 + math.degrees(y / R_EARTH)
    lon = LON0 + math.degrees(x / (R_EARTH * COS0))
    return f"{lat:.7f}", f"{lon:.7f}"


def to_local(lat, lon):
    return (R_EARTH * COS0 * math.radians(float(lon) - LON0),
            R_EARTH * math.radians(float(lat) - LAT0))


def dist(a, b):
    return math.hypot(b[0] - a[0], b[1] - a[1])


def azimuth(a, b):
    """Degrees clockwise from north of the direction a -> b."""
    return math.degrees(math.atan2(b[0] - a[0], b[1] - a[1])) % 360.0


def catmull_rom_span(p0, p1, p2, p3, steps=200):
    """Centripetal Catmull-Rom from p1 to p2 (p1 included, p2 excluded)."""
    def knot(t, a, b):
        return t + max(dist(a, b), 1e-9) ** 0.5

    t0 = 0.0
    t1 = knot(t0, p0, p1)
    t2 = knot(t1, p1, p2)
    t3 = knot(t2, p2, p3)

    def lerp(a, b, ta, tb, t):
        u = (t - ta) / (tb - ta)
        return (a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u)

    out = []
    for k in range(steps):
        t = t1 + (t2 - t1) * k / steps
        a1 = lerp(p0, p1, t0, t1, t)
        a2 = lerp(p1, p2, t1, t2, t)
        a3 = lerp(p2, p3, t2, t3, t)
        b1 = lerp(a1, a2, t0, t2, t)
        b2 = lerp(a2, a3, t1, t3, t)
        out.append(lerp(b1, b2, t1, t2, t))
    return out


def resample(dense, n):
    """n equal arc-length pieces of the polyline `dense`: the n-1 inner points."""
    cum = [0.0]
    for a, b in zip(dense, dense[1:]):
        cum.append(cum[-1] + dist(a, b))
    out, j = [], 0
    for k in range(1, n):
        s = cum[-1] * k / n
        while cum[j + 1] < s:
            j += 1
        u = (s - cum[j]) / (cum[j + 1] - cum[j])
        a, b = dense[j], dense[j + 1]
        out.append((a[0] + (b[0] - a[0]) * u, a[1] + (b[1] - a[1]) * u))
    return out, cum[-1]


def road_points(road_index, kind, closed, pts):
    """The road as a list of (key, (x, y)); key = place name or ('shape', road, k)."""
    cps = [PLACES[p] if isinstance(p, str) else p for p in pts]
    fixed = [isinstance(p, str) for p in pts]
    assert fixed[0] and fixed[-1], "a road must start and end at named points"
    out = []
    shape = 0

    def add_shape(xy):
        nonlocal shape
        out.append((("shape", road_index, shape), xy))
        shape += 1

    if kind == "line":
        for i, p in enumerate(pts):
            if i > 0:
                a, b = cps[i - 1], cps[i]
                n = math.ceil(dist(a, b) / LINE_MAX)
                for k in range(1, n):
                    add_shape((a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n))
            if fixed[i]:
                out.append((p, cps[i]))
            else:
                add_shape(cps[i])
        if closed:
            raise ValueError("closed line roads are not used")
        return out

    m = len(cps)
    if closed:
        spans = range(m)
        get = lambda i: cps[i % m]
    else:
        spans = range(m - 1)

        def get(i):
            if i < 0:
                return (2 * cps[0][0] - cps[1][0], 2 * cps[0][1] - cps[1][1])
            if i >= m:
                return (2 * cps[-1][0] - cps[-2][0], 2 * cps[-1][1] - cps[-2][1])
            return cps[i]

    out.append((pts[0], cps[0]))
    dense = []
    for i in spans:
        dense += catmull_rom_span(get(i - 1), get(i), get(i + 1), get(i + 2))
        j = (i + 1) % m
        if fixed[j]:
            dense.append(cps[j])
            n = max(1, round(resample(dense, 1)[1] / CURVE_STEP))
            for xy in resample(dense, n)[0]:
                add_shape(xy)
            out.append((pts[j], cps[j]))
            dense = []
    return out


def build():
    """Nodes (id -> (x, y)), ways and the ids of the named places."""
    roads = [road_points(i, kind, closed, pts)
             for i, (_, _, _, _, kind, closed, pts) in enumerate(ROADS)]
    degree = {}
    edges = set()
    for pts in roads:
        for (a, _), (b, _) in zip(pts, pts[1:]):
            edges.add(frozenset((a, b)))
    for e in edges:
        for k in e:
            degree[k] = degree.get(k, 0) + 1
    for name in PLACES:
        if name not in degree:
            raise ValueError(f"place {name} is on no road")
    ids = {}
    for name in PLACES:                          # junctions and road ends first
        if degree[name] != 2:
            ids[name] = len(ids) + 1
    for name in PLACES:                          # then named mid-road points
        if name not in ids:
            ids[name] = len(ids) + 1
    coords = {ids[n]: xy for n, xy in PLACES.items()}
    for pts in roads:                            # then shape points, road by road
        for key, xy in pts:
            if key not in ids:
                ids[key] = len(ids) + 1
                coords[ids[key]] = xy
    ways = []
    for (name, highway, surface, width, *_), pts in zip(ROADS, roads):
        tags = {"highway": highway, "surface": surface, "width": width, "name": name}
        ways.append((tags, [ids[k] for k, _ in pts]))
    areas = []
    for tags, poly in (({"building": "yes", "name": "Chapter House"}, BUILDING),
                       ({"natural": "wood", "name": "Casemate Grove"}, WOOD)):
        ring = []
        for xy in poly:
            nid = len(coords) + 1
            coords[nid] = xy
            ring.append(nid)
        areas.append((tags, ring + ring[:1]))
    places = {n: ids[n] for n in PLACES}
    return coords, ways, areas, places


# --- writers ---------------------------------------------------------------------------------
def esc(s):
    return (s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;"))


def osm_text(coords, ways, areas):
    ll = {i: to_latlon(*xy) for i, xy in coords.items()}
    lats = [float(a) for a, _ in ll.values()]
    lons = [float(b) for _, b in ll.values()]
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           '<osm version="0.6" generator="generate_park.py">',
           f'  <bounds minlat="{min(lats):.7f}" minlon="{min(lons):.7f}" '
           f'maxlat="{max(lats):.7f}" maxlon="{max(lons):.7f}"/>']
    for i in sorted(ll):
        out.append(f'  <node id="{i}" lat="{ll[i][0]}" lon="{ll[i][1]}"/>')
    for wid, (tags, refs) in enumerate(ways + areas, start=1):
        out.append(f'  <way id="{wid}">')
        out += [f'    <nd ref="{r}"/>' for r in refs]
        out += [f'    <tag k="{k}" v="{esc(v)}"/>' for k, v in tags.items()]
        out.append("  </way>")
    out.append("</osm>")
    return "\n".join(out) + "\n"


def gpx_text(coords, ways):
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           '<gpx version="1.1" creator="generate_park.py" '
           'xmlns="http://www.topografix.com/GPX/1/1">',
           "  <metadata>",
           "    <name>Park roads</name>",
           "    <desc>Made-up park road network (see README.md); one track per road.</desc>",
           "  </metadata>"]
    for tags, refs in ways:
        out += ["  <trk>",
                f"    <name>{esc(tags['name'])}</name>",
                f"    <desc>highway={tags['highway']} width={tags['width']}</desc>",
                f"    <type>{tags['surface']}</type>",
                "    <trkseg>"]
        for r in refs:
            lat, lon = to_latlon(*coords[r])
            out.append(f'      <trkpt lat="{lat}" lon="{lon}"/>')
        out += ["    </trkseg>", "  </trk>"]
    out.append("</gpx>")
    return "\n".join(out) + "\n"


# --- reading the files back and measuring the graph ------------------------------------------
class Graph:
    def __init__(self):
        self.xy = {}    # key -> (x, y) local metres
        self.adj = {}   # key -> {neighbour: length}

    def add_edge(self, a, b):
        if a == b:
            return
        d = dist(self.xy[a], self.xy[b])
        self.adj.setdefault(a, {})[b] = d
        self.adj.setdefault(b, {})[a] = d

    def edges(self):
        return [(a, b) for a in self.adj for b in self.adj[a] if repr(a) < repr(b)]


def parse_osm(text):
    """Road graph of an OSM file, by node id; also the lat/lon text of every node."""
    root = ET.fromstring(text)
    latlon = {int(n.get("id")): (n.get("lat"), n.get("lon")) for n in root.iter("node")}
    g = Graph()
    for way in root.iter("way"):
        tags = {t.get("k"): t.get("v") for t in way.iter("tag")}
        if "highway" not in tags:
            continue
        refs = [int(nd.get("ref")) for nd in way.iter("nd")]
        for r in refs:
            g.xy[r] = to_local(*latlon[r])
        for a, b in zip(refs, refs[1:]):
            g.add_edge(a, b)
    return g, latlon


def parse_gpx(text):
    """Road graph of a GPX file: track points with identical lat/lon text are one node."""
    ns = {"g": "http://www.topografix.com/GPX/1/1"}
    root = ET.fromstring(text)
    g = Graph()
    for seg in root.iterfind("g:trk/g:trkseg", ns):
        keys = [(p.get("lat"), p.get("lon")) for p in seg.iterfind("g:trkpt", ns)]
        for k in keys:
            g.xy[k] = to_local(*k)
        for a, b in zip(keys, keys[1:]):
            g.add_edge(a, b)
    return g


def chains(g):
    """Road stretches between nodes of degree != 2: (u, w, length, [u, ..., w])."""
    key = {n for n in g.adj if len(g.adj[n]) != 2}
    out, seen = [], set()
    for u in sorted(key, key=repr):
        for v in sorted(g.adj[u], key=repr):
            if (u, v) in seen:
                continue
            path, length = [u, v], g.adj[u][v]
            while path[-1] not in key:
                a, b = path[-2], path[-1]
                nxt = next(n for n in g.adj[b] if n != a)
                length += g.adj[b][nxt]
                path.append(nxt)
            seen.add((path[-1], path[-2]))
            out.append((u, path[-1], length, path))
    return out


def pt_seg(p, s, t):
    """Distance from point p to segment st."""
    vx, vy = t[0] - s[0], t[1] - s[1]
    u = max(0.0, min(1.0, ((p[0] - s[0]) * vx + (p[1] - s[1]) * vy) / (vx * vx + vy * vy)))
    return math.hypot(p[0] - s[0] - u * vx, p[1] - s[1] - u * vy)


def seg_dist(a, b, c, d):
    """Distance between segments ab and cd (0 when they intersect)."""
    def cross(o, p, q):
        return (p[0] - o[0]) * (q[1] - o[1]) - (p[1] - o[1]) * (q[0] - o[0])

    d1, d2, d3, d4 = cross(c, d, a), cross(c, d, b), cross(a, b, c), cross(a, b, d)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and d1 and d2 and d3 and d4:
        return 0.0

    return min(pt_seg(a, c, d), pt_seg(b, c, d), pt_seg(c, a, b), pt_seg(d, a, b))


def angle_between(o, p, q):
    a1 = math.atan2(p[1] - o[1], p[0] - o[0])
    a2 = math.atan2(q[1] - o[1], q[0] - o[0])
    d = abs(a1 - a2) % (2 * math.pi)
    return math.degrees(min(d, 2 * math.pi - d))


def measure(g):
    s = {}
    nodes = sorted(g.adj, key=repr)
    edges = g.edges()
    s["nodes"], s["edges"] = len(nodes), len(edges)
    hist = {}
    for n in nodes:
        hist[len(g.adj[n])] = hist.get(len(g.adj[n]), 0) + 1
    s["degrees"] = dict(sorted(hist.items()))
    comp, seen = 0, set()
    for n in nodes:
        if n in seen:
            continue
        comp += 1
        stack = [n]
        seen.add(n)
        while stack:
            for m in g.adj[stack.pop()]:
                if m not in seen:
                    seen.add(m)
                    stack.append(m)
    s["components"] = comp
    s["cycles"] = len(edges) - len(nodes) + comp
    s["length"] = sum(g.adj[a][b] for a, b in edges)
    s["longest_segment"] = max(g.adj[a][b] for a, b in edges)
    s["shortest_segment"] = min(g.adj[a][b] for a, b in edges)
    best = (math.inf, None, None)
    for i, a in enumerate(nodes):
        for b in nodes[i + 1:]:
            d = dist(g.xy[a], g.xy[b])
            if d < best[0]:
                best = (d, a, b)
    s["min_spacing"] = best
    best = (math.inf, None, None)
    for i, (a, b) in enumerate(edges):
        for c, d in edges[i + 1:]:
            if len({a, b, c, d}) < 4:
                continue
            dd = seg_dist(g.xy[a], g.xy[b], g.xy[c], g.xy[d])
            if dd < best[0]:
                best = (dd, (a, b), (c, d))
    s["min_segment_gap"] = best
    s["crossings"] = sum(1 for i, (a, b) in enumerate(edges) for c, d in edges[i + 1:]
                         if len({a, b, c, d}) == 4
                         and seg_dist(g.xy[a], g.xy[b], g.xy[c], g.xy[d]) == 0.0)
    junction_angle, bend_angle = (math.inf, None), (math.inf, None)
    for n in nodes:
        nb = sorted(g.adj[n], key=repr)
        for i, p in enumerate(nb):
            for q in nb[i + 1:]:
                ang = angle_between(g.xy[n], g.xy[p], g.xy[q])
                if len(nb) > 2 and ang < junction_angle[0]:
                    junction_angle = (ang, n)
                if len(nb) == 2 and ang < bend_angle[0]:
                    bend_angle = (ang, n)
    s["min_junction_angle"] = junction_angle
    s["min_bend_angle"] = bend_angle  # 180 = straight on
    ch = chains(g)
    s["chains"] = len(ch)
    s["dead_ends"] = sorted((length, u if len(g.adj[u]) == 1 else w)
                            for u, w, length, _ in ch
                            if len(g.adj[u]) == 1 or len(g.adj[w]) == 1)
    short = {}
    for u, w, length, _ in ch:
        if u != w and 8.0 <= length <= 15.0:
            short[frozenset((u, w))] = length
    tri = []
    keys = sorted({k for e in short for k in e}, key=repr)
    for i, a in enumerate(keys):
        for j, b in enumerate(keys[i + 1:], i + 1):
            for c in keys[j + 1:]:
                sides = [frozenset(p) for p in ((a, b), (b, c), (a, c))]
                if all(x in short for x in sides):
                    tri.append(((a, b, c), [short[x] for x in sides]))
    s["triangles"] = tri
    xs = [p[0] for p in g.xy.values()]
    ys = [p[1] for p in g.xy.values()]
    s["extent"] = (max(xs) - min(xs), max(ys) - min(ys))
    return s


def dijkstra(g, start, goal, ahead=None):
    """Shortest path length and nodes. With `ahead`, the robot leaves `start` towards `ahead`
    and never reverses onto the edge it came along (no U-turns anywhere)."""
    if ahead is None:
        dist_, prev = {start: 0.0}, {}
        heap = [(0.0, 0, start)]
        tie = 1
        while heap:
            d, _, u = heapq.heappop(heap)
            if d > dist_[u]:
                continue
            if u == goal:
                path = [u]
                while path[-1] != start:
                    path.append(prev[path[-1]])
                return d, path[::-1]
            for v, w in sorted(g.adj[u].items(), key=lambda kv: repr(kv[0])):
                if d + w < dist_.get(v, math.inf):
                    dist_[v], prev[v] = d + w, u
                    heapq.heappush(heap, (d + w, tie, v))
                    tie += 1
        return math.inf, []
    s0 = (ahead, start)
    dist_, prev = {s0: g.adj[start][ahead]}, {}
    heap = [(dist_[s0], 0, s0)]
    tie = 1
    while heap:
        d, _, st = heapq.heappop(heap)
        if d > dist_[st]:
            continue
        u, came = st
        if u == goal:
            path = [u]
            while st != s0:
                st = prev[st]
                path.append(st[0])
            return d, [start] + path[::-1]
        for v, w in sorted(g.adj[u].items(), key=lambda kv: repr(kv[0])):
            if v == came:
                continue
            nst = (v, u)
            if d + w < dist_.get(nst, math.inf):
                dist_[nst], prev[nst] = d + w, st
                heapq.heappush(heap, (d + w, tie, nst))
                tie += 1
    return math.inf, []


def ahead_of(g, start, toward):
    """The neighbour of `start` on the road stretch that leads to `toward`."""
    for v in sorted(g.adj[start], key=repr):
        path = [start, v]
        while len(g.adj[path[-1]]) == 2 and path[-1] != toward:
            path.append(next(n for n in g.adj[path[-1]] if n != path[-2]))
        if path[-1] == toward:
            return v
    raise ValueError(f"{toward} is not at the end of a road stretch from {start}")


def next_best(g, path, ahead):
    """Length of the best no-U-turn path that avoids at least one edge of `path`."""
    best = math.inf
    for a, b in zip(path[1:], path[2:]):       # the first edge is fixed by the start heading
        w = g.adj[a].pop(b)
        g.adj[b].pop(a)
        best = min(best, dijkstra(g, path[0], path[-1], ahead)[0])
        g.adj[a][b] = g.adj[b][a] = w
    return best


def routes(g, key_of):
    """For every route: start, heading, goal, no-U-turn length and path, shortest length/path."""
    out = []
    for key, title, start, toward, goal in ROUTES:
        s, t = key_of(start), key_of(goal)
        ahead = ahead_of(g, s, key_of(toward))
        fwd, fpath = dijkstra(g, s, t, ahead)
        free, path = dijkstra(g, s, t)
        out.append({"key": key, "title": title, "start": start, "goal": goal, "toward": toward,
                    "heading": azimuth(g.xy[s], g.xy[ahead]), "forward": fwd, "fpath": fpath,
                    "shortest": free, "path": path, "ahead": ahead,
                    "next_best": next_best(g, fpath, ahead)})
    return out


def inside(pt, poly):
    x, y = pt
    c = False
    for (x1, y1), (x2, y2) in zip(poly, poly[1:] + poly[:1]):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            c = not c
    return c


def poly_dist(pt, poly):
    if inside(pt, poly):
        return 0.0
    return min(pt_seg(pt, a, b) for a, b in zip(poly, poly[1:] + poly[:1]))


ZONES = [
    ("tree cover", "natural=wood polygon", lambda p: inside(p, WOOD)),
    ("building edge", "within 10 m of the building footprint", lambda p: poly_dist(p, BUILDING) <= 10.0),
    ("EM interference", "circle", lambda p: dist(p, EM_SPOT[0]) <= EM_SPOT[1]),
]


def exposure(g, path, test, step=0.25):
    """Metres of `path` whose points satisfy `test`."""
    total = 0.0
    for a, b in zip(path, path[1:]):
        pa, pb = g.xy[a], g.xy[b]
        n = max(1, math.ceil(g.adj[a][b] / step))
        for k in range(n):
            u = (k + 0.5) / n
            if test((pa[0] + (pb[0] - pa[0]) * u, pa[1] + (pb[1] - pa[1]) * u)):
                total += g.adj[a][b] / n
    return total


# --- requirements, report, README ------------------------------------------------------------
def curve_spacing(coords, ways):
    """Shortest and longest piece between consecutive points of `curve` roads."""
    pieces = []
    for road, (_, refs) in zip(ROADS, ways):
        if road[4] == "curve":
            pieces += [dist(coords[a], coords[b]) for a, b in zip(refs, refs[1:])]
    return min(pieces), max(pieces)


def requirements(g, s, rts, coords, ways):
    """The list of broken requirements (empty when all hold)."""
    bad = []
    key_nodes = sum(c for d, c in s["degrees"].items() if d != 2)

    def need(ok, what):
        if not ok:
            bad.append(what)

    need(key_nodes >= 30, f"{key_nodes} junctions/ends, want >= 30")
    need(sum(c for d, c in s["degrees"].items() if d >= 4) >= 2, "want two junctions of degree >= 4")
    need(s["cycles"] >= 3, f"{s['cycles']} independent cycles, want >= 3")
    need(s["components"] == 1, f"{s['components']} components")
    need(len(s["triangles"]) >= 1, "no triangle junction")
    need(s["longest_segment"] <= 25.0, f"segment of {s['longest_segment']:.1f} m")
    need(s["min_spacing"][0] >= 3.0, f"nodes {s['min_spacing'][1:]} {s['min_spacing'][0]:.2f} m apart")
    need(s["crossings"] == 0, f"{s['crossings']} road crossings without a node")
    need(s["min_junction_angle"][0] >= 25.0,
         f"junction angle {s['min_junction_angle'][0]:.1f} deg at {s['min_junction_angle'][1]}")
    need(s["dead_ends"][0][0] >= 15.0, f"dead end {s['dead_ends'][0]}")
    lo, hi = curve_spacing(coords, ways)
    need(8.0 <= lo and hi <= 15.0, f"curve spacing {lo:.1f}-{hi:.1f} m")
    need(270 <= s["extent"][0] <= 330 and 220 <= s["extent"][1] <= 280, f"extent {s['extent']}")
    allxy = list(coords.values())
    m = min(dist(a, b) for i, a in enumerate(allxy) for b in allxy[i + 1:])
    need(m >= 3.0, f"area node {m:.2f} m from another node")
    walls = list(zip(BUILDING, BUILDING[1:] + BUILDING[:1]))
    gap = min(seg_dist(g.xy[u], g.xy[v], a, b) for u, v in g.edges() for a, b in walls)
    need(4.0 <= gap <= 10.0 and not any(inside(g.xy[n], BUILDING) for n in g.adj),
         f"the building is {gap:.1f} m from the nearest road centreline, want 4-10 m")
    r = {x["key"]: x for x in rts}
    need(330 <= r["long"]["forward"] <= 380, f"long route {r['long']['forward']:.1f} m")
    need(170 <= r["short"]["forward"] <= 210, f"short route {r['short']['forward']:.1f} m")
    need(r["short"]["path"][1] != r["short"]["ahead"], "short route needs no U-turn")
    need(150 <= r["third"]["forward"] <= 300, f"third route {r['third']['forward']:.1f} m")
    for x in rts:
        need(x["next_best"] - x["forward"] >= 10.0, f"{x['key']} route: next best path "
             f"{x['next_best']:.1f} m is within 10 m of {x['forward']:.1f} m")
    return bad


def report(name, s, label=str):
    deg = s["degrees"]
    lines = [f"{name}: {s['nodes']} nodes, {s['edges']} edges, {s['components']} component(s), "
             f"{s['cycles']} independent cycles (E - V + C), {s['length']:.1f} m of road",
             "  nodes by degree: " + ", ".join(f"{d}: {c}" for d, c in deg.items())
             + f"  (junctions and road ends, degree != 2: "
             f"{sum(c for d, c in deg.items() if d != 2)}; degree >= 4: "
             f"{sum(c for d, c in deg.items() if d >= 4)})",
             f"  road stretches between junctions/ends: {s['chains']}",
             f"  segments {s['shortest_segment']:.2f}-{s['longest_segment']:.2f} m, "
             f"min node spacing {s['min_spacing'][0]:.2f} m "
             f"({label(s['min_spacing'][1])}, {label(s['min_spacing'][2])}), "
             f"min gap between non-adjacent segments {s['min_segment_gap'][0]:.2f} m, "
             f"crossings without a node: {s['crossings']}",
             f"  min angle between roads at a junction {s['min_junction_angle'][0]:.1f} deg "
             f"(at {label(s['min_junction_angle'][1])}), "
             f"sharpest bend {180 - s['min_bend_angle'][0]:.1f} deg",
             f"  shortest dead end {s['dead_ends'][0][0]:.1f} m, "
             f"extent {s['extent'][0]:.1f} x {s['extent'][1]:.1f} m"]
    for (a, b, c), sides in s["triangles"]:
        lines.append(f"  triangle {label(a)}, {label(b)}, {label(c)}: sides "
                     + ", ".join(f"{x:.2f}" for x in sides) + " m")
    return "\n".join(lines)


def route_report(rts, label=str):
    lines = []
    for r in rts:
        lines.append(f"  {r['title']}: {label(r['fpath'][0])} heading {r['heading']:.1f} deg -> "
                     f"{label(r['fpath'][-1])}: no U-turn {r['forward']:.1f} m, "
                     f"shortest {r['shortest']:.1f} m, next-best other path {r['next_best']:.1f} m")
    return "\n".join(lines)


def compare(g_osm, latlon, g_gpx):
    """Problems found when comparing the OSM graph with the GPX graph."""
    e1 = {frozenset((latlon[a], latlon[b])) for a, b in g_osm.edges()}
    e2 = {frozenset(e) for e in g_gpx.edges()}
    s1 = sum(g_osm.adj[a][b] for a, b in g_osm.edges())
    s2 = sum(g_gpx.adj[a][b] for a, b in g_gpx.edges())
    bad = []
    if len(g_osm.adj) != len(g_gpx.adj):
        bad.append(f"node counts differ: {len(g_osm.adj)} vs {len(g_gpx.adj)}")
    if e1 != e2:
        bad.append(f"edge sets differ: {len(e1 - e2)} only in OSM, {len(e2 - e1)} only in GPX")
    if abs(s1 - s2) > 0.1:
        bad.append(f"total lengths differ: {s1:.2f} vs {s2:.2f}")
    return bad


def fmt_xy(xy):
    return f"({xy[0]:.1f}, {xy[1]:.1f})"


def readme_text(coords, ways, areas, place_ids, g, s, rts):
    names = {v: k for k, v in place_ids.items()}
    n_shape = len(g.adj) - len(place_ids)
    first_area = max(g.adj) + 1
    key_count = sum(1 for n in place_ids.values() if len(g.adj[n]) != 2)
    deg = s["degrees"]
    lines = [
        "# Roads",
        "",
        "Road maps for outdoor navigation: a car-like robot drives along park roads from a start to",
        "a goal using the road map, GPS and a compass. Regenerate everything with",
        "",
        "```sh",
        "python3 assets/roads/generate_park.py          # writes park/park.osm, park/park.gpx and this README",
        "python3 assets/roads/generate_park.py --check  # re-reads both files, rebuilds both graphs, prints",
        "                                               # the numbers below; exit 1 if anything is off",
        "```",
        "",
        "The generator is standard-library Python 3.11 and deterministic. Do not edit the files by hand.",
        "",
        "## park/ — a made-up fortress park, about 300 m × 250 m",
        "",
        "The layout mirrors the Vyšehrad park in Prague (the thesis's test site) in spirit only: it is",
        "designed in local metres in `generate_park.py` and **not** copied from OpenStreetMap. An asphalt",
        "main loop (*Rampart Road*, 5 m) runs round the fortress; *Basilica Avenue* (asphalt, 4 m) crosses",
        "it west–east from the West Gate to the East Gate, and *Chapter Road* (paving stones, 3.5 m)",
        "north–south from the North Gate to the casemates; gravel paths (2.5–3 m) fill the quarters,",
        "follow the ramparts (*Bastion Walk*, *Casemate Path*) and lead to lookouts. In the south-east",
        "quarter *Orchard Path* forks into a triangle of three 12 m paths.",
        "",
        "| file | what |",
        "|---|---|",
        f"| `park/park.osm` | OpenStreetMap XML 0.6: `<bounds>`, {len(coords)} nodes, {len(ways)} road ways "
        "(tags `highway` ∈ footway/path/service/pedestrian, `surface` ∈ asphalt/gravel/paving_stones, "
        f"`width` in metres, `name`) and two closed area ways the road importer must ignore: way "
        f"{len(ways) + 1} `building=yes` (*Chapter House*) and way {len(ways) + 2} `natural=wood` "
        "(*Casemate Grove*). "
        "A junction is one node shared by every way that meets there; *Rampart Road* is a closed way "
        "(first node = last node). |",
        f"| `park/park.gpx` | GPX 1.1, one `<trk>` per road way, in the same order, with `<name>`, "
        "`<desc>` (`highway=… width=…`), `<type>` (the surface) and one `<trkseg>`. A point shared by "
        "several tracks has exactly the same `lat`/`lon` text in each, so merging identical points "
        "rebuilds the OSM graph. |",
        "| `generate_park.py` | the layout, the writers and the `--check` verification |",
        "",
        "### Coordinates",
        "",
        f"Reference point (local origin): **lat {LAT0:.6f}, lon {LON0:.6f}**; local x points east, y",
        "north, in metres. Latitude/longitude follow from the equirectangular projection",
        "",
        "    x_east  = R·cos(lat0)·(lon − lon0)·π/180",
        f"    y_north = R·(lat − lat0)·π/180,   R = {R_EARTH:.0f} m",
        "",
        "(inverted for writing), with 7 decimals (about 1 cm). All lengths below are measured in this",
        "local frame from the written coordinates.",
        "",
        "### Graph (from `--check`; the OSM and the GPX graph are identical)",
        "",
        f"- {s['nodes']} nodes, {s['edges']} edges, one component, "
        f"**{s['cycles']} independent cycles** (E − V + C), {s['length']:.1f} m of road.",
        f"- Nodes by degree: " + ", ".join(f"{c} of degree {d}" for d, c in deg.items())
        + f" — {sum(c for d, c in deg.items() if d != 2)} junctions and road ends, "
        f"{sum(c for d, c in deg.items() if d >= 4)} of them where four roads meet.",
        f"- Pieces between consecutive points {s['shortest_segment']:.1f}–{s['longest_segment']:.1f} m "
        f"(straight pieces ≤ {LINE_MAX:.0f} m; curves sampled every "
        f"{curve_spacing(coords, ways)[0]:.1f}–{curve_spacing(coords, ways)[1]:.1f} m); "
        f"nodes at least {s['min_spacing'][0]:.1f} m apart; segments that share no node at least "
        f"{s['min_segment_gap'][0]:.1f} m apart (roads meet only at shared nodes).",
        f"- Roads meeting at a junction are at least {s['min_junction_angle'][0]:.1f}° apart; the "
        f"sharpest bend along a road turns by {180 - s['min_bend_angle'][0]:.1f}°; the shortest "
        f"dead end is {s['dead_ends'][0][0]:.1f} m.",
    ]
    for (a, b, c), sides in s["triangles"]:
        lines.append(f"- Triangle junction: nodes {a}, {b}, {c} ({names[a]}, {names[b]}, {names[c]}), "
                     "sides " + ", ".join(f"{x:.1f}" for x in sides) + " m.")
    lines += [
        "",
        "### Node ids",
        "",
        f"Ids 1–{key_count} are the junctions and road ends (degree ≠ 2) in the order of the table "
        f"below; {key_count + 1} is a named mid-road point; "
        f"{len(place_ids) + 1}–{len(place_ids) + n_shape} are the shape points, road by road in "
        f"way order; {first_area}–{len(coords)} are the corners of the two areas. Way ids: "
        f"1–{len(ways)} roads in the order of the road table, then the building and the wood.",
        "",
        "| id | name | x, y (m) | lat | lon | degree |",
        "|---:|---|---|---|---|---:|",
    ]
    for name, nid in place_ids.items():
        lat, lon = to_latlon(*coords[nid])
        lines.append(f"| {nid} | `{name}` | {fmt_xy(coords[nid])} | {lat} | {lon} | {len(g.adj[nid])} |")
    lines += [
        "",
        "### Roads",
        "",
        "| way | name | highway | surface | width (m) | length (m) | through |",
        "|---:|---|---|---|---:|---:|---|",
    ]
    for wid, (tags, refs) in enumerate(ways, start=1):
        length = sum(g.adj[a][b] for a, b in zip(refs, refs[1:]))
        via = " → ".join(str(r) for r in refs if r in names)
        lines.append(f"| {wid} | {tags['name']} | {tags['highway']} | {tags['surface']} | "
                     f"{tags['width']} | {length:.1f} | {via} |")
    lines += [
        "",
        "## Routes",
        "",
        "Three robots can drive at once. Headings are azimuths, degrees clockwise from north, of",
        "the first road piece the robot faces. *No U-turn* is the shortest path of a planner that",
        "leaves the start in its heading's direction and never reverses along the edge it came on;",
        "*shortest* is the unconstrained shortest path (Dijkstra). *Next best* is the best no-U-turn",
        "path that differs from it in at least one edge (a margin against importers that measure",
        "lengths slightly differently).",
        "",
        "| route | start | heading | goal | no U-turn (m) | shortest (m) | next best (m) |",
        "|---|---|---:|---|---:|---:|---:|",
    ]
    for r in rts:
        st, gl = r["fpath"][0], r["fpath"][-1]
        lines.append(f"| {r['title']} | {st} `{names[st]}` | {r['heading']:.1f}° | {gl} `{names[gl]}` | "
                     f"{r['forward']:.1f} | {r['shortest']:.1f} | {r['next_best']:.1f} |")
    lines.append("")
    for r in rts:
        via = " → ".join(f"{n} `{names[n]}`" for n in r["fpath"] if n in names)
        lines.append(f"- **{r['title']}** (no U-turn): {via}.")
        if r["path"] != r["fpath"]:
            via = " → ".join(f"{n} `{names[n]}`" for n in r["path"] if n in names)
            lines.append(f"  The unconstrained shortest path turns back: {via}.")
    short = next(r for r in rts if r["key"] == "short")
    st = short["fpath"][0]
    behind = [st, next(n for n in g.adj[st] if n != short["ahead"])]
    while len(g.adj[behind[-1]]) == 2:
        behind.append(next(n for n in g.adj[behind[-1]] if n != behind[-2]))
    ahead_end = place_ids[short["toward"]]
    lines += [
        "",
        f"The short route's start, node {st} `{names[st]}`, lies in the middle of the *Orchard Path* "
        f"stretch between {ahead_end} `{names[ahead_end]}` and {behind[-1]} `{names[behind[-1]]}` "
        f"({dijkstra(g, st, ahead_end)[0]:.1f} m and {dijkstra(g, st, behind[-1])[0]:.1f} m away); "
        "the robot faces the avenue, away from the goal. Without a U-turn it drives on to the "
        "avenue, east to the loop and round the loop's south-east arc "
        f"({short['forward']:.1f} m instead of {short['shortest']:.1f} m).",
        "",
        "## Suggested GPS / compass degradation zones (local metres)",
        "",
        "Not part of the road data; a scenario may use them. Metres of each route inside each zone",
        "(along the no-U-turn path) are listed.",
        "",
        "| zone | shape | " + " | ".join(r["title"] for r in rts) + " |",
        "|---|---|" + "---:|" * len(rts),
    ]
    shapes = {
        "tree cover": "polygon " + ", ".join(fmt_xy(p) for p in WOOD)
        + f" — the `natural=wood` way {len(ways) + 2}, over the gravel *Casemate Path* "
        "(casemate_fork → loop) and the *South Steps*",
        "building edge": "footprint " + ", ".join(fmt_xy(p) for p in BUILDING)
        + f" (40 m × 15 m, the `building=yes` way {len(ways) + 1}), 6 m east of *Chapter Road* and "
        "about 10 m south of the loop's north arc; degrade GPS within 10 m of it",
        "EM interference": f"circle centre {fmt_xy(EM_SPOT[0])}, radius {EM_SPOT[1]:.0f} m, "
        f"around junction {place_ids['avenue_east']} `avenue_east` (compass disturbed)",
    }
    for zname, _, test in ZONES:
        lines.append(f"| {zname} | {shapes[zname]} | "
                     + " | ".join(f"{exposure(g, r['fpath'], test):.1f}" for r in rts) + " |")
    lines += [
        "",
        "An importer must build the road graph from ways with a `highway` tag only; the two area",
        "ways have none.",
        "",
    ]
    return "\n".join(lines)


def check_files(place_ids, coords, ways):
    """Re-read both files, rebuild both graphs, print the numbers; the list of problems."""
    g, latlon = parse_osm(OSM_PATH.read_text(encoding="utf-8"))
    h = parse_gpx(GPX_PATH.read_text(encoding="utf-8"))
    names = {v: k for k, v in place_ids.items()}
    label = lambda n: f"{n} {names[n]}" if n in names else str(n)
    s = measure(g)
    rts = routes(g, lambda p: place_ids[p])
    print(report(f"OSM {OSM_PATH.relative_to(HERE.parent.parent)}", s, label))
    print(route_report(rts, label))
    gl = {latlon[i]: i for i in g.adj}
    glabel = lambda k: label(gl[k]) if k in gl else str(k)
    sg = measure(h)
    rg = routes(h, lambda p: latlon[place_ids[p]])
    print(report(f"GPX {GPX_PATH.relative_to(HERE.parent.parent)}", sg, glabel))
    print(route_report(rg, glabel))
    bad = compare(g, latlon, h)
    for a, b in zip(rts, rg):
        if abs(a["forward"] - b["forward"]) > 0.01 or abs(a["shortest"] - b["shortest"]) > 0.01:
            bad.append(f"{a['key']} route differs between OSM and GPX")
    bad += requirements(g, s, rts, coords, ways)
    if not bad:
        print(f"OSM and GPX graphs identical: {s['nodes']} nodes, {s['edges']} edges, "
              f"{s['length']:.2f} m vs {sg['length']:.2f} m; all requirements hold")
    return bad


def main():
    check = "--check" in sys.argv[1:]
    coords, ways, areas, place_ids = build()
    osm, gpx = osm_text(coords, ways, areas), gpx_text(coords, ways)
    g, _ = parse_osm(osm)
    s = measure(g)
    rts = routes(g, lambda p: place_ids[p])
    readme = readme_text(coords, ways, areas, place_ids, g, s, rts)
    files = {OSM_PATH: osm, GPX_PATH: gpx, README_PATH: readme}
    bad = []
    if check:
        for path, text in files.items():
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                bad.append(f"{path.relative_to(HERE)} differs from the generator's output")
    else:
        pre = requirements(g, s, rts, coords, ways)
        if pre:
            for b in pre:
                print("FAIL:", b, file=sys.stderr)
            sys.exit(1)
        OUT.mkdir(parents=True, exist_ok=True)
        for path, text in files.items():
            path.write_text(text, encoding="utf-8", newline="\n")
            print("wrote", path.relative_to(HERE.parent.parent))
    if OSM_PATH.exists() and GPX_PATH.exists():
        bad += check_files(place_ids, coords, ways)
    for b in bad:
        print("FAIL:", b, file=sys.stderr)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
