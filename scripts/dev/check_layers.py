#!/usr/bin/python3
"""The include directions of the layers (doc/dev/extending.md): a header or source of one layer includes
only its own layer and those below it, and the MPM's deal.II layer and the FEM stage share only the
hand-over header. Prints every include that breaks the rule and exits 1 if there is one.

  core                      physics, step, backends: no deal.II, nothing above
  handover, fields, cuda    the hand-over state, random fields, the device engine: the core only
  dealii, fem               the MPM on deal.II, the pre-failure FEM: the layers above, not each other
  run                       the scene of one prm file and the FEM-then-MPM run: everything below
  app                       the executable

Usage: check_layers.py [REPOSITORY]   (default: the repository this script is in)
"""
import os
import re
import sys

root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
allowed = {
    "core": {"core"},
    "handover": {"core", "handover"},
    "fields": {"core", "fields"},
    "cuda": {"core", "cuda"},
    "dealii": {"core", "handover", "fields", "cuda", "dealii"},
    "fem": {"core", "handover", "fem"},
    "run": {"core", "handover", "fields", "cuda", "dealii", "fem", "run"},
}
include = re.compile(r'^\s*#\s*include\s*<mpm/([a-z_]+)/')
broken = []
checked = 0
for top, layer_of in (("include/mpm", lambda parts: parts[0]), ("source", lambda parts: parts[0])):
    for directory, _, files in os.walk(os.path.join(root, top)):
        relative = os.path.relpath(directory, os.path.join(root, top))
        if relative == ".":
            continue
        layer = layer_of(relative.split(os.sep))
        if layer not in allowed:
            broken.append(f"{top}/{relative}: a folder of no known layer (add it to check_layers.py)")
            continue
        for name in files:
            if not name.endswith((".h", ".cc", ".cu", ".inc")):
                continue
            path = os.path.join(directory, name)
            checked += 1
            with open(path, encoding="utf-8") as f:
                for number, line in enumerate(f, 1):
                    m = include.match(line)
                    if m and m.group(1) not in allowed[layer]:
                        broken.append(f"{os.path.relpath(path, root)}:{number}: layer '{layer}' includes "
                                      f"mpm/{m.group(1)}/ (allowed: {', '.join(sorted(allowed[layer]))})")
for line in broken:
    print(line)
print(f"{checked} files checked, {len(broken)} include(s) against the layers")
sys.exit(1 if broken else 0)
