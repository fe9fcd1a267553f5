"""The README's Python example runs as written."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[3] / "README.md"


def test_the_readme_python_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert len(blocks) == 1, "one Python example in the README"
    scope: dict = {}
    exec(compile(blocks[0], "README.md", "exec"), scope)
    summary = scope["summary"]
    assert summary["scenario"] == "maze_run" and summary["sim_time_s"] == 60.0
    assert summary["robots"][0]["distance_m"] > 5.0
