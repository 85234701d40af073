#!/usr/bin/env python3
"""Checks the dependency rule of ARCHITECTURE.md: every module of src/ uses only its own folder and
the folders above it in the pipeline, and no two modules import each other in a circle.
src/error/ (the crate-wide error that wraps every layer's failures) stands outside the rule.
The binary (src/bin/jointrom/) has its own rule: main -> cli -> commands/* -> the shared modules
(args, common, summary); a command never uses another command or cli, the shared modules use no
command, and nothing in the binary forms a circle.
Prints violations and exits non-zero if there are any. Doc comments are ignored."""
import glob, os, re, sys

ORDER = ["error", "files", "linalg", "case", "mesh", "element", "assembly", "joint", "model", "system",
         "reduction", "integrate", "rom", "studies", "report"]
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")

def module_of(path):
    rel = os.path.relpath(path, root)[:-3].split(os.sep)
    if rel[-1] == "mod":
        rel = rel[:-1]
    return rel

def code(text):
    return "\n".join(l for l in text.split("\n") if not l.lstrip().startswith("//"))

bad = []
edges = {}
for f in glob.glob(os.path.join(root, "**", "*.rs"), recursive=True):
    mod = module_of(f)
    if mod[0] in ("lib", "main", "bin", "error"):
        continue
    top = mod[0]
    text = code(open(f).read())
    targets = set()
    for m in re.finditer(r"crate::((?:[a-z_0-9]+::)*[a-z_0-9]+)", text):
        targets.add(tuple(m.group(1).split("::")))
    for m in re.finditer(r"\bsuper::((?:[a-z_0-9]+::)*[a-z_0-9]+)", text):
        parent = mod[:-1] if os.path.basename(f) != "mod.rs" else mod[:-1]
        targets.add(tuple(parent) + tuple(m.group(1).split("::")))
    for t in targets:
        if t[0] not in ORDER:
            continue
        if ORDER.index(t[0]) > ORDER.index(top):
            bad.append(f"{'/'.join(mod)} -> {'::'.join(t)} (upward: {top} may not use {t[0]})")
        edges.setdefault("/".join(mod), set()).add(t)

# file-level circles: resolve each target to the longest existing module prefix
mods = {"/".join(module_of(f)) for f in glob.glob(os.path.join(root, "**", "*.rs"), recursive=True)}
graph = {}
for a, ts in edges.items():
    for t in ts:
        for k in range(len(t), 0, -1):
            b = "/".join(t[:k])
            if b in mods:
                if b != a and not a.startswith(b + "/"):
                    graph.setdefault(a, set()).add(b)
                break
seen, stack, cycles = set(), [], []
def dfs(v, on):
    seen.add(v); on.append(v)
    for w in graph.get(v, ()):
        if w in on:
            cycles.append(on[on.index(w):] + [w])
        elif w not in seen:
            dfs(w, on)
    on.pop()
for v in sorted(graph):
    if v not in seen:
        dfs(v, [])
for c in cycles:
    bad.append("circle: " + " -> ".join(c))

# The binary: main -> cli -> commands/* -> shared modules; no command uses another or cli.
BIN_ORDER = ["main", "cli", "commands", "shared"]
bin_root = os.path.join(root, "bin", "jointrom")
def bin_layer(mod):
    return mod[0] if mod[0] in ("main", "cli", "commands") else "shared"
bin_graph = {}
for f in glob.glob(os.path.join(bin_root, "**", "*.rs"), recursive=True):
    rel = os.path.relpath(f, bin_root)[:-3].split(os.sep)
    if rel[-1] == "mod":
        rel = rel[:-1]
    if not rel:
        continue
    text = code(open(f).read())
    targets = {tuple(m.group(1).split("::"))
               for m in re.finditer(r"crate::((?:[a-z_0-9]+::)*[a-z_0-9]+)", text)}
    targets |= {tuple(rel[:-1]) + tuple(m.group(1).split("::"))
                for m in re.finditer(r"\bsuper::((?:[a-z_0-9]+::)*[a-z_0-9]+)", text)}
    here = "/".join(rel)
    for t in targets:
        there = "/".join(t[:2]) if t[0] == "commands" and len(t) > 1 else t[0]
        if there == here or (t[0] == "commands" and rel[0] == "commands" and len(t) == 1):
            continue
        a, b = bin_layer(rel), bin_layer(t)
        if BIN_ORDER.index(b) < BIN_ORDER.index(a) or (a == b == "commands" and there != here):
            bad.append(f"bin/{here} -> {'::'.join(t)} (binary: {a} may not use {b})")
        bin_graph.setdefault(here, set()).add(there)
bseen = set()
def bdfs(v, on):
    bseen.add(v); on.append(v)
    for w in bin_graph.get(v, ()):
        if w in on:
            bad.append("circle in the binary: " + " -> ".join(on[on.index(w):] + [w]))
        elif w not in bseen:
            bdfs(w, on)
    on.pop()
for v in sorted(bin_graph):
    if v not in bseen:
        bdfs(v, [])
for b in sorted(set(bad)):
    print(b)
sys.exit(1 if bad else 0)
