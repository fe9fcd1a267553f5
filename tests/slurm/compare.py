"""Checks that a merged sharded batch equals the same batch run whole.

    python3 compare.py MERGED WHOLE

Compares the two `sim batch` output folders: every row of runs.jsonl and runs.csv field by
field as written (so bit for bit), the rows of aggregate.csv, and batch.json. Wall-clock
figures differ from run to run and are skipped: the row fields `job_wall_s`, `wall_time_s`
and `real_time_factor` (also per robot, should they appear there), and the aggregate rows of
those metrics. batch.json is compared apart from its `shard`/`shards` fields. Prints what it
compared and the first difference; exits 1 on a difference. Standard library only.
"""

import csv
import json
import re
import sys

# Wall-clock fields: the only ones allowed to differ between two runs of one job.
TIMING = re.compile(r"(^|\.)(job_wall_s|wall_time_s|real_time_factor)$")
# batch.json fields that say which shard a folder is.
SHARD_FIELDS = ("shard", "shards")


class Differ(Exception):
    pass


def literal(s):
    """Keeps a JSON number as the text written, so equal means bit for bit."""
    return ("number", s)


def show(v):
    """A value as written in the file."""
    return v[1] if isinstance(v, tuple) else json.dumps(v)


def read_jsonl(path):
    with open(path, encoding="utf-8") as f:
        return [
            json.loads(line, parse_float=literal, parse_int=literal)
            for line in f
            if line.strip()
        ]


def read_csv(path):
    with open(path, encoding="utf-8", newline="") as f:
        return list(csv.reader(f))


def compare_rows(name, merged, whole, key_of):
    """Compares two lists of dict rows by key; returns (compared, skipped) field counts."""
    if len(merged) != len(whole):
        raise Differ(f"{name}: {len(merged)} rows merged, {len(whole)} whole")
    compared = skipped = 0
    for i, (m, w) in enumerate(zip(merged, whole)):
        where = f"{name} row {i} ({key_of(w)})"
        if key_of(m) != key_of(w):
            raise Differ(f"{where}: the merged row is {key_of(m)}")
        if set(m) != set(w):
            only_m = sorted(set(m) - set(w))
            only_w = sorted(set(w) - set(m))
            raise Differ(f"{where}: fields only merged {only_m}, only whole {only_w}")
        for k in w:
            if TIMING.search(k):
                skipped += 1
                continue
            compared += 1
            if m[k] != w[k]:
                raise Differ(f"{where}, {k}: merged {show(m[k])}, whole {show(w[k])}")
    return compared, skipped


def main(merged_dir, whole_dir):
    # runs.jsonl: one object per job, in job order
    merged = read_jsonl(f"{merged_dir}/runs.jsonl")
    whole = read_jsonl(f"{whole_dir}/runs.jsonl")
    jobs = [w.get("job") for w in whole]
    if jobs != [literal(str(i)) for i in range(len(whole))]:
        raise Differ(f"whole runs.jsonl: jobs not 0..{len(whole)} in order")
    n, s = compare_rows("runs.jsonl", merged, whole, lambda r: f"job {show(r['job'])}")
    print(f"runs.jsonl: {len(whole)} rows, {n} fields equal, {s} wall-clock fields skipped")

    # runs.csv: the same rows as columns (a header, then one line per job)
    mh, *mr = read_csv(f"{merged_dir}/runs.csv")
    wh, *wr = read_csv(f"{whole_dir}/runs.csv")
    if mh != wh:
        raise Differ(f"runs.csv header: merged {mh}, whole {wh}")
    n, s = compare_rows(
        "runs.csv",
        [dict(zip(mh, r)) for r in mr],
        [dict(zip(wh, r)) for r in wr],
        lambda r: f"job {r['job']}",
    )
    print(f"runs.csv: {len(wr)} rows, {n} fields equal, {s} wall-clock fields skipped")

    # aggregate.csv: statistics per parameter set and metric; wall-clock metrics skipped
    mh, *mr = read_csv(f"{merged_dir}/aggregate.csv")
    wh, *wr = read_csv(f"{whole_dir}/aggregate.csv")
    if mh != wh:
        raise Differ(f"aggregate.csv header: merged {mh}, whole {wh}")
    metric = wh.index("metric")
    mr = [r for r in mr if not TIMING.search(r[metric])]
    kept = [r for r in wr if not TIMING.search(r[metric])]
    n, _ = compare_rows(
        "aggregate.csv",
        [dict(zip(mh, r)) for r in mr],
        [dict(zip(wh, r)) for r in kept],
        lambda r: f"set {r['set']} {r['metric']}",
    )
    print(
        f"aggregate.csv: {len(kept)} metric rows, {n} fields equal, "
        f"{len(wr) - len(kept)} wall-clock rows skipped"
    )

    # batch.json: the batch's description, apart from which shard it is
    with open(f"{merged_dir}/batch.json", encoding="utf-8") as f:
        mb = json.load(f)
    with open(f"{whole_dir}/batch.json", encoding="utf-8") as f:
        wb = json.load(f)
    strip = lambda b: {k: v for k, v in b.items() if k not in SHARD_FIELDS}  # noqa: E731
    if strip(mb) != strip(wb):
        keys = sorted(set(mb) | set(wb))
        k = next(k for k in keys if k not in SHARD_FIELDS and mb.get(k) != wb.get(k))
        raise Differ(f"batch.json, {k}: merged {mb.get(k)!r}, whole {wb.get(k)!r}")
    print(f"batch.json: {len(strip(wb))} fields equal ({', '.join(SHARD_FIELDS)} not compared)")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    try:
        main(sys.argv[1], sys.argv[2])
    except Differ as e:
        print(f"DIFFERENCE: {e}", file=sys.stderr)
        sys.exit(1)
    print("merged shards equal the whole batch")
