#!/usr/bin/env bash
# bench/map.sh - the mapping of cells onto workers: a slowed worker (--slow 1:K, the
# runtime spins K-1 times the time it worked: an emulated slower machine) under block
# and weighted mappings (lambda of busy time and total compute time), and 64 cells on
# 2 workers, greedy vs block (lambda, and the messages between the workers: a ray
# entering a cell of its own worker is handed on inline, no message, so every
# cell-to-cell message counted here crossed to the other worker and the fewer the
# better). Usage: bench/map.sh [OUTDIR]; VW_BUILD_DIR picks the build.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
OUT=${1:-$(dirname "${BASH_SOURCE[0]}")/out/map}
SIZE=${SIZE:-256x256}
mkdir -p "$OUT"
# Scratch (the rendered images, each run's stats) goes to T, removed at exit.
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$VWALLS" gen spheres --count 1000 --cluster 0.5 --seed 7 -o "$OUT/cluster50.nff"
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(' '.join(str(eval('d'+k)) for k in sys.argv[2:]))" "$@"; }

echo "| case | map | λ busy | λ work (speed-weighted) | compute s | messages between workers |"
echo "|---|---|---|---|---|---|"
for k in 2 4; do
  for m in block weighted; do
    "$VWALLS" render "$OUT/cluster50.nff" -o "$T/img.png" --size "$SIZE" --cells 4x4x2 \
      --workers 2 --map "$m" --slow "1:$k" --quiet --stats "$T/s.json"
    read -r lb lw c xm < <(json "$T/s.json" "['balance']['imbalance']" \
      "['balance_detail']['imbalance_work']" "['time_s']['compute']" \
      "['traffic']['messages'] - d['traffic']['worker_messages']")
    echo "| 32 cells, worker 1 slowed ${k}x | $m | $lb | $lw | $c | $xm |"
  done
done
for m in block greedy; do
  "$VWALLS" render "$OUT/cluster50.nff" -o "$T/img.png" --size "$SIZE" --cells 4x4x4 \
    --workers 2 --map "$m" --quiet --stats "$T/s.json" --overlay "$OUT/map_$m.png" --overlay-by worker
  read -r lb lw c xm < <(json "$T/s.json" "['balance']['imbalance']" \
    "['balance_detail']['imbalance_work']" "['time_s']['compute']" \
    "['traffic']['messages'] - d['traffic']['worker_messages']")
  echo "| 64 cells on 2 workers | $m | $lb | $lw | $c | $xm |"
done
