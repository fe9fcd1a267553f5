"""The benchmark script runs (with tiny sizes: its figures are measured by hand, not here)."""

import importlib.util
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "benches" / "bench.py"


def test_every_benchmark_of_the_script_runs():
    spec = importlib.util.spec_from_file_location("bench", BENCH)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    bench.REPEATS = 1
    assert bench.step_overhead(ticks=20)["engine_tick_us"] > 0
    assert bench.python_loop_rtf(steps=5)["beams"] == 1081
    assert bench.gym_reset_ms()["reset_ms"] > 0
    rows = bench.vector_throughput(worlds=2, ticks=20)
    assert [(r["worlds"], r["threads"]) for r in rows] == [(1, 1), (2, 1), (2, 2)]
