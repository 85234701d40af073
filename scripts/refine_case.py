#!/usr/bin/env python3
"""Writes refined copies of a case file: every sheet's element counts multiplied by each factor
(both in-plane directions), everything else unchanged (the scaling study).

    python3 scripts/refine_case.py cases/friction_bar.json cases/scale 2 4 8 13

writes cases/scale/friction_bar_x2.json ... _x13.json (name suffixed `_xF`). The DOF count grows
about as F² (6 per node, (F·nx + 1)(F·nz + 1) nodes per sheet).

    python3 scripts/refine_case.py --window 0.01 0.004 cases/friction_bar.json cases/scale 4 8 13

writes the short-window variants of the full-FE references at scale (`_xF_window`): the load's
ramp shortened to RAMP s and the end time to END s, so that the window carries the whole load
(see cases/reference/scale/SOURCE.md)."""
import json, os, sys

args = sys.argv[1:]
window = None
if args[:1] == ["--window"]:
    window = (float(args[1]), float(args[2]))
    args = args[3:]
if len(args) < 3:
    sys.exit("usage: refine_case.py [--window RAMP END] CASE.json OUT_DIR FACTOR...")
src, out_dir, factors = args[0], args[1], [int(f) for f in args[2:]]
case = json.load(open(src))
stem = os.path.splitext(os.path.basename(src))[0]
os.makedirs(out_dir, exist_ok=True)
for f in factors:
    if f < 1:
        sys.exit(f"factor {f}: must be >= 1")
    c = json.loads(json.dumps(case))
    suffix = f"_x{f}" + ("_window" if window else "")
    c["name"] = f"{case['name']}{suffix}"
    c["description"] = f"{case.get('description', '')} Refined {f}x per direction (scripts/refine_case.py)."
    if window:
        c["load"]["ramp"]["duration"], c["end_time"] = window
        c["description"] += f" Short window: load ramp {window[0]} s, end time {window[1]} s."
    nodes = 0
    for s in c["sheets"]:
        s["elements"] = [f * e for e in s["elements"]]
        nodes += (s["elements"][0] + 1) * (s["elements"][1] + 1)
    path = os.path.join(out_dir, f"{stem}{suffix}.json")
    with open(path, "w") as fh:
        json.dump(c, fh, indent=2, ensure_ascii=False)
        fh.write("\n")
    print(f"{path}: elements {[s['elements'] for s in c['sheets']]}, ~{6 * nodes} DOF before constraints")
