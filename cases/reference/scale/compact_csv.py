#!/usr/bin/env python3
"""Compacts a `jointrom transient --out DIR` run into a stored scale reference: OUT.csv with the
compared curves (t s, contact_force_norm N, friction_force_norm N, master_uy mm; 10 significant
digits) and OUT.run.json beside it with the command, options, CVODE statistics, profile, wall
and CPU time and, if given, the `/usr/bin/time -f "%e s %M KB"` line of the run.

    compact_csv.py DIR OUT "COMMAND" ["TIME LINE"]"""
import csv, json, sys

src, dst, command = sys.argv[1], sys.argv[2], sys.argv[3]
time_line = sys.argv[4] if len(sys.argv) > 4 else None
d = json.load(open(src + "/transient.json"))
c = d["curves"]
cols = ["t", "contact_force_norm", "friction_force_norm", "master_uy"]
with open(dst + ".csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(cols)
    for row in zip(*(c[k] for k in cols)):
        w.writerow([f"{x:.10g}" for x in row])
run = {k: d.get(k) for k in ["case", "model", "basis_size", "options", "stats", "profile", "wall_s", "cpu_s"]}
run["command"] = command
run["time"] = time_line
run["outputs"] = len(c["t"])
with open(dst + ".run.json", "w") as f:
    json.dump(run, f, indent=1)
    f.write("\n")
