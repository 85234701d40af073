#!/usr/bin/env python3
"""Writes a copy of a case file on another mesh, optionally with its welds moved or resized (the
weld-footprint study of docs/validation/contact-refinement.md).

    python3 scripts/mesh_case.py cases/multilayer_sheet.json /tmp/ml_s20.json 108 20
    python3 scripts/mesh_case.py cases/multilayer_sheet.json /tmp/ml_s20_shift.json 108 20 --shift-x 0.3125
    python3 scripts/mesh_case.py cases/multilayer_sheet.json /tmp/ml_s20_d55.json 108 20 --diameter 5.5

sets every sheet's `elements` to [NX, NZ], adds DX (mm) to every weld's x, sets every weld's
diameter to D (mm); everything else unchanged (name suffixed `_NXxNZ`)."""
import argparse, json

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("case")
ap.add_argument("out")
ap.add_argument("nx", type=int, help="elements along x per sheet")
ap.add_argument("nz", type=int, help="elements along z per sheet")
ap.add_argument("--shift-x", type=float, default=0.0, help="added to every weld's x (mm)")
ap.add_argument("--diameter", type=float, help="every weld's diameter (mm)")
a = ap.parse_args()
if a.nx < 1 or a.nz < 1:
    ap.error("NX and NZ must be >= 1")
if a.diameter is not None and not a.diameter > 0.0:
    ap.error("--diameter must be > 0")
case = json.load(open(a.case))
case["name"] = f"{case['name']}_{a.nx}x{a.nz}"
what = [f"meshed {a.nx} x {a.nz} per sheet"]
for s in case["sheets"]:
    s["elements"] = [a.nx, a.nz]
for w in case.get("welds", []):
    w["x"] += a.shift_x
    if a.diameter is not None:
        w["diameter"] = a.diameter
if a.shift_x:
    what.append(f"welds moved by {a.shift_x} mm in x")
if a.diameter is not None:
    what.append(f"weld diameter {a.diameter} mm")
case["description"] = f"{case.get('description', '')} Variant: {', '.join(what)} (scripts/mesh_case.py)."
with open(a.out, "w") as fh:
    json.dump(case, fh, indent=2, ensure_ascii=False)
    fh.write("\n")
print(f"{a.out}: {', '.join(what)}")
