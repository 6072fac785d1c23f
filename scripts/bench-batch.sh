#!/bin/sh
# Throughput of many renders (issue "many renders at frame cost"), on this machine:
#   1. 30 teapot renders at 256² as 30 processes against one `sunshade batch` of the same 30 jobs;
#   2. the whole `render` process of the teapot at 1024² against its own render + readback + encode phases.
# Each figure is the median of RUNS runs (default 5). Usage: scripts/bench-batch.sh [RUNS]
set -eu
cd "$(dirname "$0")/.."
S=target/release/sunshade
RUNS=${1:-5}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
python3 - "$TMP" <<'PY'
import json, sys
d = sys.argv[1]
json.dump([{"scene": "models/teapot.glb", "output": f"{d}/b{i}.png", "width": 256, "height": 256,
            "sun-azimuth": i * 12} for i in range(30)], open(f"{d}/jobs.json", "w"))
PY
now() { date +%s.%N; }
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
for r in $(seq "$RUNS"); do
    t0=$(now)
    for i in $(seq 0 29); do
        $S render models/teapot.glb -o "$TMP/p$i.png" --width 256 --height 256 --sun-azimuth $((i * 12)) 2>/dev/null
    done
    t1=$(now)
    $S batch "$TMP/jobs.json" -q
    t2=$(now)
    echo "$t0 $t1 $t2" | awk '{printf "%.4f %.4f\n", $2 - $1, $3 - $2}'
done > "$TMP/batch.txt"
procs=$(cut -d' ' -f1 "$TMP/batch.txt" | median)
batch=$(cut -d' ' -f2 "$TMP/batch.txt" | median)
echo "30 teapot renders at 256x256: 30 processes ${procs} s, one batch ${batch} s (median of $RUNS): $(echo "$procs $batch" | awk '{printf "%.1f", $1 / $2}')x"
for r in $(seq "$RUNS"); do
    $S render models/teapot.glb -o "$TMP/t.png" --width 1024 --height 1024 -v 2>&1 |
        awk '/^  (render|readback|encode) /{s += $2} /^  total /{t = $2} END {printf "%.2f %.2f\n", t, s}'
done > "$TMP/process.txt"
total=$(cut -d' ' -f1 "$TMP/process.txt" | median)
frame=$(cut -d' ' -f2 "$TMP/process.txt" | median)
echo "teapot 1024x1024 PNG: whole process ${total} ms, render + readback + encode ${frame} ms (medians of $RUNS): $(echo "$total $frame" | awk '{printf "%.2f", $1 / $2}')x"
