#!/usr/bin/env python3
"""Writes refined copies of a case file: every sheet's element counts multiplied by each factor
(both in-plane directions), everything else unchanged (the scaling study of issue 18).

    python3 scripts/refine_case.py cases/friction_bar.json cases/scale 2 4 8 13

writes cases/scale/friction_bar_x2.json ... _x13.json (name suffixed `_xF`). The DOF count grows
about as F² (6 per node, (F·nx + 1)(F·nz + 1) nodes per sheet)."""
import json, os, sys

if len(sys.argv) < 4:
    sys.exit("usage: refine_case.py CASE.json OUT_DIR FACTOR...")
src, out_dir, factors = sys.argv[1], sys.argv[2], [int(f) for f in sys.argv[3:]]
case = json.load(open(src))
stem = os.path.splitext(os.path.basename(src))[0]
os.makedirs(out_dir, exist_ok=True)
for f in factors:
    if f < 1:
        sys.exit(f"factor {f}: must be >= 1")
    c = json.loads(json.dumps(case))
    c["name"] = f"{case['name']}_x{f}"
    c["description"] = f"{case.get('description', '')} Refined {f}x per direction (scripts/refine_case.py)."
    nodes = 0
    for s in c["sheets"]:
        s["elements"] = [f * e for e in s["elements"]]
        nodes += (s["elements"][0] + 1) * (s["elements"][1] + 1)
    path = os.path.join(out_dir, f"{stem}_x{f}.json")
    with open(path, "w") as fh:
        json.dump(c, fh, indent=2, ensure_ascii=False)
        fh.write("\n")
    print(f"{path}: elements {[s['elements'] for s in c['sheets']]}, ~{6 * nodes} DOF before constraints")
