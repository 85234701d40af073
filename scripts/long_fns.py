#!/usr/bin/env python3
"""Lists functions longer than a limit (default 150 lines, signature to closing brace) in the
given Rust files or folders (default: src/)."""
import glob, os, re, sys
limit = 150
paths = [a for a in sys.argv[1:] if not a.startswith("--")] or ["src"]
files = []
for p in paths:
    files += glob.glob(os.path.join(p, "**", "*.rs"), recursive=True) if os.path.isdir(p) else [p]
found = 0
for f in sorted(files):
    lines = open(f).read().split("\n")
    for i, l in enumerate(lines):
        m = re.match(r"^(\s*)(pub(\([a-z]+\))? )?(const )?(unsafe )?(extern \"C\" )?fn (\w+)", l)
        if not m:
            continue
        indent = m.group(1)
        for j in range(i, len(lines)):
            if lines[j] == indent + "}" or (j == i and lines[j].rstrip().endswith("}")):
                break
            if j > i and lines[j].startswith(indent) and lines[j].rstrip().endswith(";") and j == i:
                break
        n = j - i + 1
        if n > limit:
            found += 1
            print(f"{f}:{i + 1}: {m.group(7)} {n} lines")
sys.exit(1 if found else 0)
