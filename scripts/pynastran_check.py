#!/usr/bin/env python3
"""Cross-checks jointrom's reading of NASTRAN decks against pyNastran (an independent reader).

    python3 scripts/pynastran_check.py [DECK.bdf ...]   (default: cases/nastran/*.bdf decks)

For each deck, pyNastran's `read_bdf` and `jointrom info DECK --json` must agree on: the grids
that carry DOF (those used by CQUAD4, CBAR/CBEAM, RBE2, CONM2, CGAP and ALIGN welds), the number
of CQUAD4 shells, of area welds (CWELD other than ALIGN), of CGAP pairs (jointrom's pairs plus
those it reports fused by a weld), of clamped grids (SPC1/SPC of the selected set, GRID PS) and
of RBE2 dependent grids; the structural mass (ρ t A of the shells and the CONM2 masses, from
pyNastran's parsed fields) to 1e-9; the master load (FORCE/MOMENT of the TLOAD1's EXCITEID set, times the DLOAD scales) and
the end time (TSTEP) to 1e-12. Exits non-zero on the first disagreement; prints one line per deck.

pyNastran comes from PyPI (`pip install pyNastran`); jointrom from `cargo build --release`.
"""

import glob
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def jointrom_info(deck):
    exe = os.path.join(ROOT, "target", "release", "jointrom")
    out = subprocess.run([exe, "info", deck, "--json"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout), out.stderr


def cweld_locations(deck, cards):
    """The number of distinct locations (GS grid, or XS YS ZS) of the deck's CWELD area-weld
    cards (ALIGN welds are point welds, not counted), read from the deck's text in fixed or free
    field format; `cards` (pyNastran's count) if the text gives none."""
    locations = set()
    with open(deck) as f:
        lines = f.read().splitlines()
    for i, line in enumerate(lines):
        if not line.upper().startswith("CWELD"):
            continue
        if "," in line:
            fields = [x.strip() for x in line.split(",")]
        else:
            fields = [line[k : k + 8].strip() for k in range(0, len(line), 8)]
        if len(fields) > 4 and fields[4].upper() == "ALIGN":
            continue
        gs = fields[3] if len(fields) > 3 else ""
        if gs:
            locations.add(("GS", gs))
        else:
            # XS YS ZS on the continuation line (fields 2-4 there).
            nxt = lines[i + 1] if i + 1 < len(lines) else ""
            locations.add(("XS", nxt[8:32].strip()))
    return len(locations) if locations else cards


def check(deck):
    from pyNastran.bdf.bdf import read_bdf

    model = read_bdf(deck, xref=False, debug=None)
    info, stderr = jointrom_info(deck)
    problems = []

    def same(what, ours, theirs, tol=0.0):
        if isinstance(ours, (int,)) and isinstance(theirs, (int,)) and tol == 0.0:
            ok = ours == theirs
        else:
            ok = abs(ours - theirs) <= tol * max(abs(theirs), 1e-300)
        if not ok:
            problems.append(f"{what}: jointrom {ours}, pyNastran {theirs}")

    quads = [e for e in model.elements.values() if e.type == "CQUAD4"]
    beams = [e for e in model.elements.values() if e.type in ("CBAR", "CBEAM")]
    gaps = [e for e in model.elements.values() if e.type == "CGAP"]
    # pyNastran 1.4 does not type CWELD: count the cards it read (rejected or not).
    welds = [e for e in model.elements.values() if e.type == "CWELD"] or [None] * model.card_count.get("CWELD", 0)
    rbe2 = [r for r in model.rigid_elements.values() if r.type == "RBE2"]
    used = set()
    for e in quads + beams + gaps:
        used |= set(e.node_ids)
    for r in rbe2:
        used |= {r.gn} | set(r.Gmi)
    for m in model.masses.values():
        used.add(m.nid)
    same("nodes", info["nodes"], len(used))
    same("shells", info["shells"], len(quads))
    # jointrom merges the CWELDs of one location through a stack of sheets (same GS) into one
    # area weld: count the locations of the cards pyNastran read.
    same("area welds (one per location)", info["area_welds"], cweld_locations(deck, len(welds)))
    fused = 0
    for w in info["warnings"]:
        if "nugget" in w:
            inside = w[w.index("[") + 1 : w.index("]")]
            fused = len([x for x in inside.split(",") if x.strip()])
    same("CGAP pairs (jointrom's + fused)", info["joint_pairs"] + fused, len(gaps))
    same("RBE2 dependent grids", info["tied_nodes"], sum(len(r.Gmi) for r in rbe2))

    spc_grids = set()
    for sets in model.spcs.values():
        for spc in sets:
            spc_grids |= set(spc.node_ids)
    spc_grids |= {nid for nid, g in model.nodes.items() if str(g.ps).strip() == "123456"}
    same("clamped grids", info["clamped_nodes"], len(spc_grids & used))

    # Mass from pyNastran's parsed fields: rho t A per CQUAD4 (A = |d1 x d2| / 2), plus CONM2.
    mass = 0.0
    for e in quads:
        x = [model.nodes[n].xyz for n in e.node_ids]
        d1 = [x[2][k] - x[0][k] for k in range(3)]
        d2 = [x[3][k] - x[1][k] for k in range(3)]
        c = [d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0]]
        prop = model.properties[e.pid]
        rho = model.materials[prop.mid1].rho
        mass += rho * prop.t * 0.5 * sum(v * v for v in c) ** 0.5
    mass += sum(m.mass for m in model.masses.values())
    same("structural mass (t)", info["structural_mass"], mass, 1e-9)

    load = [0.0] * 6
    for dload_sets in model.dloads.values():
        for dload in dload_sets:
            for scale, lid in zip(dload.scale_factors, dload.load_ids):
                for tload in model.dload_entries[lid]:
                    for entry in model.loads.get(tload.excite_id, []):
                        off = 3 if entry.type == "MOMENT" else 0
                        for k in range(3):
                            load[off + k] += dload.scale * scale * entry.mag * entry.xyz[k]
    if not model.dloads:
        for tloads in model.dload_entries.values():
            for tload in tloads:
                for entry in model.loads.get(tload.excite_id, []):
                    off = 3 if entry.type == "MOMENT" else 0
                    for k in range(3):
                        load[off + k] += entry.mag * entry.xyz[k]
    for k in range(6):
        same(f"master load [{k}]", info["master_load"][k], load[k], 1e-12)
    tsteps = list(model.tsteps.values())
    if tsteps:
        end = sum(n * dt for n, dt in zip(tsteps[0].N, tsteps[0].DT))
        same("end time (s)", info["end_time"], end, 1e-12)

    name = os.path.relpath(deck, ROOT)
    if problems:
        print(f"{name}: DISAGREE\n  " + "\n  ".join(problems))
        return False
    print(
        f"{name}: agree — {info['nodes']} nodes, {info['shells']} CQUAD4, {info['area_welds']} CWELD, "
        f"{len(gaps)} CGAP ({fused} fused), mass {info['structural_mass']:.9e} t, "
        f"load {info['master_load']}, end {info['end_time']} s"
    )
    return True


def main():
    decks = sys.argv[1:] or sorted(
        d for d in glob.glob(os.path.join(ROOT, "cases", "nastran", "*.bdf")) if not d.endswith("_mesh.bdf")
    )
    ok = all([check(d) for d in decks])
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
