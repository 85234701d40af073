#!/usr/bin/env python3
"""Compacts a `jointrom transient --out DIR` result (DIR/transient.json) into a stored reference:
the compared curves (‖f_c‖, ‖f_R‖, master u_y, dissipated energy D) at the run's output times (10 significant digits) plus the run's
options, statistics and wall time.  Usage: compact.py DIR OUT.json [COMMAND]"""
import json, sys

src, dst = sys.argv[1], sys.argv[2]
d = json.load(open(src + "/transient.json"))
c = d["curves"]
r = lambda xs: [float(f"{x:.10g}") for x in xs]
out = {
    "case": d["case"],
    "model": d["model"],
    "basis_size": d["basis_size"],
    "command": sys.argv[3] if len(sys.argv) > 3 else None,
    "options": d["options"],
    "stats": d["stats"],
    "wall_s": d["wall_s"],
    "cpu_s": d["cpu_s"],
    "units": {"t": "s", "contact_force_norm": "N", "friction_force_norm": "N", "master_uy": "mm", "dissipated": "N mm"},
    "t": r(c["t"]),
    "contact_force_norm": r(c["contact_force_norm"]),
    "friction_force_norm": r(c["friction_force_norm"]),
    "master_uy": r(c["master_uy"]),
    "dissipated": r(c["dissipated"]),
}
json.dump(out, open(dst, "w"), separators=(",", ":"))
