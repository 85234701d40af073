#!/usr/bin/env bash
# The scaling table: `jointrom info` and `jointrom basis` (default a-priori g) on the
# friction bar and its refinements, wall time and max RSS from /usr/bin/time, and the log–log
# slopes between consecutive rows. Run from the repository root after `cargo build --release`:
#
#     python3 scripts/refine_case.py cases/friction_bar.json cases/scale 2 4 8 13
#     scripts/scale_table.sh [FACTOR...]        # default: 1 2 4 8 13
#     SCENE=multilayer_sheet scripts/scale_table.sh 1 2 4 8 15
#
# Every run is limited to 16 GB of address space (ulimit -v); a run that fails prints its exit
# status instead of figures.
set -u
bin=target/release/jointrom
scene=${SCENE:-friction_bar}
factors=${*:-1 2 4 8 13}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
rows=()
for f in $factors; do
    if [ "$f" = 1 ]; then case=cases/$scene.json; else case=cases/scale/${scene}_x$f.json; fi
    "$bin" info --json "$case" > "$tmp/info.json" || exit 1
    dofs=$(python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); print(d["dofs"], d["joint_pairs"])' "$tmp/info.json")
    row="$f $dofs"
    for cmd in info basis; do
        if /usr/bin/time -f "%e %M" -o "$tmp/time" bash -c "ulimit -v 16000000; exec $bin $cmd $case > $tmp/$cmd.out 2>&1"; then
            read -r s kb < "$tmp/time"
            row="$row $s $((kb / 1024))"
        else
            row="$row fail($(tail -1 "$tmp/time")) -"
        fi
    done
    rows+=("$row")
    echo "$row" >&2
done
printf '%s\n' "${rows[@]}" | python3 -c '
import math, sys
rows = [l.split() for l in sys.stdin if l.strip()]
print("| refinement | DOF | pairs | info s | info MB | basis s | basis MB | slope basis s | slope basis MB |")
print("|---|---|---|---|---|---|---|---|---|")
prev = None
for r in rows:
    f, n, w, si, mi, sb, mb = r
    slope = ["", ""]
    if prev and "fail" not in sb and "fail" not in prev[5]:
        k = math.log(int(n) / int(prev[1]))
        slope = ["%.2f" % (math.log(float(sb) / float(prev[5])) / k),
                 "%.2f" % (math.log(float(mb) / float(prev[6])) / k)]
    print(f"| x{f} | {n} | {w} | {si} | {mi} | {sb} | {mb} | {slope[0]} | {slope[1]} |")
    prev = r
# The slope over the whole 10^4 .. 10^5 range: first row with >= 10 000 DOF to the last row.
big = [r for r in rows if int(r[1]) >= 10000]
if len(big) >= 2 and all("fail" not in r[5] for r in (big[0], big[-1])):
    a, b = big[0], big[-1]
    k = math.log(int(b[1]) / int(a[1]))
    fmt = lambda i: "%.2f" % (math.log(float(b[i]) / float(a[i])) / k)
    print(f"\nlog-log slope x{a[0]} -> x{b[0]} ({a[1]} -> {b[1]} DOF): info time {fmt(3)}, "
          f"info memory {fmt(4)}, basis time {fmt(5)}, basis memory {fmt(6)}")
'
