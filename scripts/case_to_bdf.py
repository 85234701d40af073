#!/usr/bin/env python3
"""Writes a jointrom case file as a NASTRAN bulk data deck, the way a pre-processor writes one.

    python3 scripts/case_to_bdf.py cases/friction_bar.json cases/nastran/friction_bar.bdf

The deck is the same structure as the case, meshed by the same rule (sheet s, node (i, k) at
x0 + i (x1 - x0)/nx, z0 + k (z1 - z0)/nz), in the forms pre-processors write: executive and case
control (SOL 129, SPC, DLOAD, TSTEP), the grids and shells in an INCLUDEd file, GRID* in large
field, CQUAD4 in small field, MAT1/PSHELL in free field, continuations on RBE2, CWELD and TABLED1,
SPC1 with THRU, one PSHELL per sheet (a pre-processor's "part"; property and element ids unique across kinds,
as NASTRAN requires), CWELD PARTPAT with a location
grid GS per weld (one CWELD per pair of consecutive sheets of a stack) and PWELD, CGAP + PGAP at
every coincident node pair of each joint that is neither clamped nor tied (those inside a weld
nugget included: jointrom leaves them out, as it does for a case), FORCE/MOMENT at the RBE2's
independent grid with TLOAD1 + TABLED1 (the half-cosine ramp sampled at 201 points) and TSTEP,
plus cards jointrom ignores (PARAM, EIGRL). Only the Python standard library is used.
"""

import json
import math
import os
import sys


def f8(x):
    """A real in at most 8 characters (small field), NASTRAN style (7.85-9)."""
    x = float(x)
    s = repr(x)
    if "e" not in s and len(s) <= 8:
        return s
    for digits in range(7, -1, -1):
        m, e = f"{x:.{digits}e}".split("e")
        exp = int(e)
        if "." not in m:
            m += "."
        m = m.rstrip("0") if "." in m else m
        t = f"{m}{'+' if exp >= 0 else '-'}{abs(exp)}"
        if len(t) <= 8:
            return t
    raise ValueError(x)


def f16(x):
    """A real in at most 16 characters (large field)."""
    s = repr(float(x))
    if "e" in s:
        m, e = s.split("e")
        exp = int(e)
        if "." not in m:
            m += "."
        s = f"{m}{'+' if exp >= 0 else '-'}{abs(exp)}"
    if len(s) > 16:
        s = f"{float(x):.9e}".replace("e", "E")
    return s


def small(name, fields):
    """A small-field card: 8 fields per line, '+' continuations."""
    fields = [("" if f is None else str(f)) for f in fields]
    lines = []
    head = name
    while True:
        chunk, fields = fields[:8], fields[8:]
        lines.append(f"{head:<8}" + "".join(f"{c:>8}" for c in chunk).rstrip())
        head = "+"
        if not fields:
            return "\n".join(lines)


def large(name, fields):
    """A large-field card: 4 fields per line, '*' continuations."""
    fields = [("" if f is None else str(f)) for f in fields]
    lines = []
    head = name + "*"
    while True:
        chunk, fields = fields[:4], fields[4:]
        lines.append(f"{head:<8}" + "".join(f"{c:>16}" for c in chunk).rstrip())
        head = "*"
        if not fields:
            return "\n".join(lines)


def free(name, fields):
    return ",".join([name] + [("" if f is None else str(f)) for f in fields])


class Sheet:
    def __init__(self, s, spec):
        self.s = s
        self.name = spec["name"]
        self.x0, self.x1 = spec["x"]
        self.z0, self.z1 = spec["z"]
        self.y = spec["y"]
        self.t = spec["thickness"]
        self.nx, self.nz = spec["elements"]

    def node_id(self, i, k):
        return 10000 * (self.s + 1) + i * (self.nz + 1) + k + 1

    def xz(self, i, k):
        return (self.x0 + i * (self.x1 - self.x0) / self.nx, self.z0 + k * (self.z1 - self.z0) / self.nz)

    def nodes(self):
        for i in range(self.nx + 1):
            for k in range(self.nz + 1):
                yield i, k

    def line(self, x):
        """The node line i at x, or None."""
        for i in range(self.nx + 1):
            if abs(self.xz(i, 0)[0] - x) <= 1e-6:
                return i
        return None


def ramp_points(ramp, end):
    if ramp["shape"] != "half_cosine":
        return ramp["points"]
    T = ramp["duration"]
    n = 200
    pts = [(T * j / n, 0.5 * (1.0 - math.cos(math.pi * j / n))) for j in range(n + 1)]
    pts.append((max(end, 2.0 * T), 1.0))
    return pts


def write(case, out):
    sheets = [Sheet(s, spec) for s, spec in enumerate(case["sheets"])]
    by_name = {sh.name: sh for sh in sheets}
    mat = case["material"]
    stem = os.path.splitext(os.path.basename(out))[0]
    mesh_name = f"{stem}_mesh.bdf"
    main, mesh = [], []

    mesh.append(f"$ {case['name']}: grids and shells (included by {stem}.bdf)")
    for sh in sheets:
        mesh.append(f"$ sheet {sh.name}: PSHELL {sh.s + 1}")
        for i, k in sh.nodes():
            x, z = sh.xz(i, k)
            mesh.append(large("GRID", [sh.node_id(i, k), "", f16(x), f16(sh.y), f16(z)]))
        for i in range(sh.nx):
            for k in range(sh.nz):
                eid = 100000 * (sh.s + 1) + i * sh.nz + k + 1
                g = [sh.node_id(i, k), sh.node_id(i + 1, k), sh.node_id(i + 1, k + 1), sh.node_id(i, k + 1)]
                mesh.append(small("CQUAD4", [eid, sh.s + 1] + g))

    cmd = f"python3 scripts/case_to_bdf.py {case.get('_file', 'CASE')} {out}"
    main += [
        f"$ {case['name']} as NASTRAN bulk data, written by",
        f"$   {cmd}",
        "SOL 129",
        "CEND",
        f"TITLE = {case['name']}",
        "SPC = 1",
        "DLOAD = 10",
        "TSTEP = 20",
        "BEGIN BULK",
        "PARAM,POST,-1",
        small("EIGRL", [99, "", "", 10]),
        f"INCLUDE '{mesh_name}'",
        free("MAT1", [1, f8(mat["youngs_modulus"]), "", f8(mat["poisson_ratio"]), f8(mat["density"])]),
    ]
    for sh in sheets:
        main.append(free("PSHELL", [sh.s + 1, 1, f8(sh.t), 1, "", 1]))

    tie = case["rigid_tie"]
    tied = set()
    for name in tie["sheets"]:
        sh = by_name[name]
        i = sh.line(tie["x"])
        tied |= {sh.node_id(i, k) for k in range(sh.nz + 1)}
    clamped = set()
    for c in case["clamps"]:
        for name in c["sheets"]:
            sh = by_name[name]
            i = sh.line(c["x"])
            clamped |= {sh.node_id(i, k) for k in range(sh.nz + 1)}

    master = 90001
    mx, my, mz = tie["master"]
    main.append(large("GRID", [master, "", f16(mx), f16(my), f16(mz)]))
    main.append(small("RBE2", [1, master, 123456] + sorted(tied)))
    ids = sorted(clamped)
    runs, start = [], ids[0]
    for a, b in zip(ids, ids[1:] + [None]):
        if b != a + 1:
            runs.append((start, a))
            start = b
    for lo, hi in runs:
        main.append(small("SPC1", [1, 123456, lo, "THRU", hi] if hi > lo + 1 else [1, 123456] + list(range(lo, hi + 1))))

    main.append(small("PWELD", [101, 1, f8(case["welds"][0]["diameter"]) if case["welds"] else "5.", "", "", "OFF", "", "SPOT"]))
    weld_ids = 0
    nuggets = []
    for w, weld in enumerate(case["welds"]):
        gs = 80001 + w
        stack = [by_name[n] for n in weld["sheets"]]
        y = stack[0].y
        main.append(large("GRID", [gs, "", f16(weld["x"]), f16(y), f16(weld["z"])]))
        for lo, hi in zip(stack, stack[1:]):
            weld_ids += 1
            main.append(small("CWELD", [60000 + weld_ids, 101, gs, "PARTPAT", "", "", "", "", lo.s + 1, hi.s + 1]))
        nuggets.append(weld)

    main.append(small("PGAP", [201, "", "", f8(case["contact"]["normal_stiffness"]), "",
                               f8(case["contact"]["stick_stiffness"]), f8(case["contact"]["friction_coefficient"]),
                               f8(case["contact"]["friction_coefficient"])]))
    gap = 70000
    for j in case["joints"]:
        lo, up = by_name[j["lower"]], by_name[j["upper"]]
        upper_at = {}
        for i, k in up.nodes():
            x, z = up.xz(i, k)
            upper_at[(round(x, 6), round(z, 6))] = up.node_id(i, k)
        for i, k in lo.nodes():
            x, z = lo.xz(i, k)
            u = upper_at.get((round(x, 6), round(z, 6)))
            a = lo.node_id(i, k)
            if u is None or a in clamped | tied or u in clamped | tied:
                continue
            gap += 1
            main.append(small("CGAP", [gap, 201, a, u, 0.0, 1.0, 0.0]))

    load = case["load"]["master"]
    f = [load.get(k, 0.0) for k in ("fx", "fy", "fz")]
    m = [load.get(k, 0.0) for k in ("mx", "my", "mz")]
    fn = math.sqrt(sum(v * v for v in f))
    mn = math.sqrt(sum(v * v for v in m))
    if fn > 0:
        main.append(small("FORCE", [100, master, 0, f8(fn)] + [f8(v / fn) for v in f]))
    if mn > 0:
        main.append(small("MOMENT", [100, master, 0, f8(mn)] + [f8(v / mn) for v in m]))
    main.append(small("TLOAD1", [10, 100, "", "LOAD", 30]))
    pts = ramp_points(case["load"]["ramp"], case["end_time"])
    fields = [30, "LINEAR", "LINEAR", "", "", "", "", ""]
    for t, v in pts:
        fields += [f16(t), f16(v)]
    fields.append("ENDT")
    main.append(large("TABLED1", fields))
    dt = 1e-4
    main.append(small("TSTEP", [20, int(round(case["end_time"] / dt)), f8(dt), 1]))
    main.append("ENDDATA")

    os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
    with open(out, "w") as fh:
        fh.write("\n".join(main) + "\n")
    with open(os.path.join(os.path.dirname(out) or ".", mesh_name), "w") as fh:
        fh.write("\n".join(mesh) + "\n")


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    with open(sys.argv[1]) as fh:
        case = json.load(fh)
    case["_file"] = sys.argv[1]
    write(case, sys.argv[2])


if __name__ == "__main__":
    main()
