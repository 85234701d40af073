#!/usr/bin/env bash
# Coverage-guided fuzzing of every parser with libFuzzer (cargo-fuzz on the stable toolchain,
# with RUSTC_BOOTSTRAP=1 for the sanitizer flags cargo-fuzz passes): case files, MatrixMarket
# files, MatrixMarket files, matrix maps, reduced-model files, sweep variants, NASTRAN decks.
#   scripts/fuzz.sh [SECONDS per target, default 60] [TARGET ...]
# Prints one line per target: seconds, executions, crashes. Crashes are left in
# fuzz/artifacts/TARGET/ (replay: RUSTC_BOOTSTRAP=1 cargo fuzz run TARGET FILE).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
secs=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(case mtx map rom variants deck)

command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
export RUSTC_BOOTSTRAP=1
export JOINTROM_MAX_DOF=30000

# Seed corpora from the repository's own inputs and exports.
cargo build --release --bin jointrom -q
bin=target/release/jointrom
seeds=fuzz/seeds
rm -rf "$seeds"; mkdir -p "$seeds"/{case,mtx,map,rom,variants,deck}
cp cases/*.json "$seeds/case/"
cp cases/sweeps/*.json "$seeds/variants/"
small="$seeds/small.json"
python3 - "$small" <<'PY'
import json, sys
c = json.load(open("cases/friction_bar.json"))
c["sheets"][0]["x"] = [0.0, 120.0]
c["sheets"][1]["x"] = [40.0, 160.0]
for s in c["sheets"]:
    s["elements"] = [6, 2]
c["rigid_tie"]["x"] = 160.0
c["rigid_tie"]["master"] = [160.0, 0.5, 12.5]
# One weld: without it the upper sheet hangs on the master alone and K is singular.
c["welds"] = [{"x": 100.0, "z": 12.5, "sheets": ["A", "B"], "diameter": 5.0}]
json.dump(c, open(sys.argv[1], "w"))
PY
# Huge coordinates and sizes (checked in floating point before any allocation).
python3 - "$seeds/case" <<'PY'
import json, sys
base = json.load(open("cases/friction_bar.json"))
edits = {
    "x_1e308": lambda c: c["sheets"][0].update(x=[0.0, 1e308]),
    "x_span_overflow": lambda c: c["sheets"][0].update(x=[-1e308, 1e308]),
    "x_1e12": lambda c: c["sheets"][1].update(x=[40.0, 1e12]),
    "thin_shells": lambda c: c["sheets"][0].update(elements=[100000, 1]),
    "local_mesh_tiny": lambda c: c["welds"][0].update(local_mesh=1e-300),
}
for name, edit in edits.items():
    c = json.loads(json.dumps(base))
    edit(c)
    json.dump(c, open(f"{sys.argv[1]}/size_{name}.json", "w"))
PY
"$bin" export-matrices "$small" --out "$seeds/matrices" >/dev/null
cp "$seeds/matrices/K.mtx" "$seeds/mtx/K.mtx"; cp "$seeds/matrices/M.mtx" "$seeds/mtx/M.mtx"
cp "$seeds/matrices/model.json" "$seeds/map/model.json"
"$bin" export "$small" --g 2 --out "$seeds/rom/rom.json" >/dev/null
export JOINTROM_FUZZ_MATRICES="$PWD/$seeds/matrices"
# Decks: the small case as one file (the mesh include inlined), and the built-in scenes'.
python3 scripts/case_to_bdf.py "$small" "$seeds/deck_small/small.bdf" >/dev/null
for d in "$seeds/deck_small/small" cases/nastran/friction_bar cases/nastran/multilayer_sheet; do
  python3 - "$d" "$seeds/deck/$(basename "$d").bdf" <<'PY'
import os, sys
base, out = sys.argv[1], sys.argv[2]
text = open(base + ".bdf").read()
mesh = open(base + "_mesh.bdf").read()
name = os.path.basename(base) + "_mesh.bdf"
open(out, "w").write(text.replace(f"INCLUDE '{name}'", mesh))
PY
done

for t in "${targets[@]}"; do
  mkdir -p "fuzz/corpus/$t"
  log="fuzz/$t.log"
  set +e
  (cd fuzz && cargo fuzz run --release "$t" "corpus/$t" "../$seeds/$t" -- \
      -max_total_time="$secs" -rss_limit_mb=4096 -timeout=10 -print_final_stats=1) >"$log" 2>&1
  rc=$?
  set -e
  execs=$(grep -E '^stat::number_of_executed_units' "$log" | awk '{print $2}' | tail -1)
  crashes=$(ls "fuzz/artifacts/$t" 2>/dev/null | wc -l)
  echo "$t: ${secs} s, ${execs:-?} executions, ${crashes} crash/timeout files (exit $rc; log $log)"
done
