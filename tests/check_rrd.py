"""Prints the entity paths and timelines of an .rrd as JSON, read with the Rerun SDK (0.36.3)."""

import json
import sys

import rerun as rr


def main() -> None:
    store = rr.experimental.RrdReader(sys.argv[1]).store()
    schema = store.schema()
    paths = sorted(str(p) for p in schema.entity_paths())
    timelines = sorted({c.name for c in schema.index_columns()})
    print(json.dumps({"entity_paths": paths, "timelines": timelines}))


if __name__ == "__main__":
    main()
