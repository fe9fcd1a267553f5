"""The README's Python examples run as written."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[3] / "README.md"


def blocks():
    return re.findall(r"```python\n(.*?)```", README.read_text(), re.S)


def test_the_readme_python_examples_run():
    found = blocks()
    assert len(found) == 2, "a scripting example and a Gymnasium one"
    scope: dict = {}
    exec(compile(found[0], "README.md", "exec"), scope)
    summary = scope["summary"]
    assert summary["scenario"] == "maze_run" and summary["sim_time_s"] == 60.0
    assert summary["robots"][0]["distance_m"] > 5.0
    scope = {}
    exec(compile(found[1], "README.md", "exec"), scope)
    assert scope["obs"].shape == (16, 93) and scope["reward"].shape == (16,)
