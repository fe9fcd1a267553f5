"""Writes hospital_delivery made to last: SECONDS of simulated time with the robots at work.

    python3 long_delivery.py ASSETS/scenarios/hospital_delivery.toml OUT.toml SECONDS

The bundled run ends once its tasks are done (about 520 s). Here each robot's task list is
repeated, the task names numbered, so that the robots deliver for the whole run; the run no
longer ends when they are done, and the map paths are made absolute. Standard library only.
"""

import re
import sys

src, dst, duration = sys.argv[1], sys.argv[2], float(sys.argv[3])
lines = open(src).read().split("\n")
repeats = max(1, int(duration / 400) + 1)
out, i = [], 0
while i < len(lines):
    if lines[i] != "[[robots.tasks]]":
        out.append(lines[i])
        i += 1
        continue
    # a robot's tasks: from its first [[robots.tasks]] to the next blank line, comment or table
    block = []
    while i < len(lines) and lines[i] and not lines[i].startswith("#") and (
        lines[i] == "[[robots.tasks]]" or not lines[i].startswith("[")
    ):
        block.append(lines[i])
        i += 1
    for k in range(repeats):
        out.extend(re.sub(r'^name = "(.*)"$', rf'name = "\1_{k}"', line) for line in block)
text = "\n".join(out)
assert "end_when_done = true" in text, "the scenario no longer ends when done: check this script"
text = text.replace("end_when_done = true", "end_when_done = false")
text = re.sub(r"^duration = .*$", f"duration = {duration}", text, count=1, flags=re.M)
text = text.replace('"../maps/', '"' + src.rsplit("/scenarios/", 1)[0] + "/maps/")
open(dst, "w").write(text)
