"""Prints the entity paths and timelines of an .rrd as JSON, read with the Rerun SDK (0.36.3),
and, per entity holding `Scalars`, the number of values, their minimum, maximum and median, and
the first and last `sim_time` (seconds) they were logged at; per entity holding `TextLog`s, its
lines as `[sim_time, level, text]` in time order; per entity styled with `SeriesLines`, its
series names; and the blueprint stored in the file (`blueprint`: null without one): every view
with its class, name, origin, queries, the entities it hides and those it draws over the whole
history (visible time range from the start to the cursor), and the root's container kind."""

import json
import sys

import rerun as rr


def blueprint(reader) -> dict | None:
    """The views of the file's blueprint (the first one), or None."""
    stores = reader.blueprints()
    if not stores:
        return None
    rows: dict[str, dict] = {}
    for chunk in reader.store(store=stores[0]).stream():
        batch = chunk.to_record_batch()
        row = rows.setdefault(chunk.entity_path, {})
        for name in batch.schema.names:
            if ":" in name:
                values = batch.column(batch.schema.names.index(name)).to_pylist()
                row[name] = values[-1]
    views = {}
    for path, row in rows.items():
        parts = path.strip("/").split("/")
        if parts[0] != "view" or len(parts) != 2:
            continue
        view = {
            "class": row["ViewBlueprint:class_identifier"][0],
            "name": (row.get("ViewBlueprint:display_name") or [None])[0],
            "origin": (row.get("ViewBlueprint:space_origin") or [None])[0],
            "queries": rows.get(f"{path}/ViewContents", {}).get("ViewContents:query", []),
            "hidden": [],
            "whole_history": [],
            "properties": sorted(
                p.split("/")[-1] for p in rows if p.startswith(path + "/") and p.count("/") == 3
            ),
        }
        prefix = f"{path}/ViewContents/overrides/"
        for p, r in rows.items():
            if p.startswith(prefix) and p.endswith("/visualizers"):
                entity = "/" + p[len(prefix) : -len("/visualizers")]
                if r.get("EntityBehavior:visible") == [False]:
                    view["hidden"].append(entity)
                for rng in r.get("VisibleTimeRanges:ranges") or []:
                    if rng["range"]["start"] is None and rng["range"]["end"] == 0:
                        view["whole_history"].append(entity)
        view["hidden"].sort()
        view["whole_history"].sort()
        views[path] = view
    viewport = rows.get("/viewport", {})
    return {
        "views": sorted(views.values(), key=lambda v: (v["class"], v["name"] or "")),
        "auto_views": (viewport.get("ViewportBlueprint:auto_views") or [None])[0],
        "containers": sum(1 for p in rows if p.startswith("/container/")),
    }


def main() -> None:
    reader = rr.experimental.RrdReader(sys.argv[1])
    store = reader.store(store=reader.recordings()[0])
    schema = store.schema()
    paths = sorted(str(p) for p in schema.entity_paths())
    timelines = sorted({c.name for c in schema.index_columns()})
    values: dict[str, list[float]] = {}
    times: dict[str, list[float]] = {}
    texts: dict[str, list[list]] = {}
    series_names: dict[str, list[str]] = {}
    for chunk in store.stream():
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if "SeriesLines:names" in names:
            for row in batch.column(names.index("SeriesLines:names")).to_pylist():
                if row:
                    series_names[chunk.entity_path] = row
        if "TextLog:text" in names and "sim_time" in names:
            lines = batch.column(names.index("TextLog:text")).to_pylist()
            levels = (
                batch.column(names.index("TextLog:level")).to_pylist()
                if "TextLog:level" in names
                else [None] * len(lines)
            )
            stamps = batch.column(names.index("sim_time")).cast("int64").to_pylist()
            for line, level, t in zip(lines, levels, stamps):
                for k, text in enumerate(line or []):
                    lv = (level or [None])[min(k, len(level or [None]) - 1)]
                    texts.setdefault(chunk.entity_path, []).append([t * 1e-9, lv, text])
        if "Scalars:scalars" not in names or "sim_time" not in names:
            continue
        scalars = batch.column(names.index("Scalars:scalars")).to_pylist()
        stamps = batch.column(names.index("sim_time")).cast("int64").to_pylist()
        path = chunk.entity_path
        for row, t in zip(scalars, stamps):
            for v in row or []:
                values.setdefault(path, []).append(float(v))
                times.setdefault(path, []).append(t * 1e-9)
    scalars_out = {}
    for path, vs in values.items():
        s = sorted(vs)
        scalars_out[path] = {
            "count": len(vs),
            "min": s[0],
            "max": s[-1],
            "median": s[len(s) // 2],
            "first_t": min(times[path]),
            "last_t": max(times[path]),
        }
    for lines in texts.values():
        lines.sort(key=lambda x: x[0])
    print(
        json.dumps(
            {
                "entity_paths": paths,
                "timelines": timelines,
                "scalars": scalars_out,
                "text_logs": texts,
                "series_names": series_names,
                "blueprint": blueprint(reader),
            }
        )
    )


if __name__ == "__main__":
    main()
