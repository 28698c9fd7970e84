#!/usr/bin/env bash
# bench/core.sh - the cost of the runtime itself, measured side by side in one run with
# the example module (touching sphere pairs, an O(n log n) sweep per cell, so the local
# work hardly depends on the layout): 1 cell vs 2x2x2 cells on one worker (the price of
# decomposing: ghosts, packets, termination) and 1 vs 2 workers. Times are the compute
# phase the command reports (steps and ghosts until quiescence; generation, placement
# and cell builds excluded), best of REPS.
set -euo pipefail
. "$(dirname "$0")/lib.sh"
N=${N:-1000000}
R=${R:-0.002}
REPS=${REPS:-5}

# compute_time ARGS...: best "time" over REPS runs, and the count (must not change).
compute_time() {
  local best="" out t
  for _ in $(seq "$REPS"); do
    out=$("$VWALLS" example-pairs --spheres "$N" --radius "$R" "$@")
    count=$(echo "$out" | sed -n 's/^touching pairs: //p')
    t=$(echo "$out" | sed -n 's/.*compute \([0-9.]*\) s.*/\1/p')
    if [ -z "$best" ] || awk -v t="$t" -v b="$best" 'BEGIN { exit !(t < b) }'; then best=$t; fi
  done
  echo "$best $count"
}

read -r t1 c1 < <(compute_time --cells 1 --workers 1)
read -r t8 c8 < <(compute_time --cells 2x2x2 --workers 1)
read -r t8w2 c8w2 < <(compute_time --cells 2x2x2 --workers 2)
read -r t64 c64 < <(compute_time --cells 4x4x4 --workers 1)
read -r t64w2 c64w2 < <(compute_time --cells 4x4x4 --workers 2)
for c in "$c8" "$c8w2" "$c64" "$c64w2"; do
  [ "$c" = "$c1" ] || { echo "core bench: counts differ ($c vs $c1)" >&2; exit 1; }
done

echo "== runtime cost: example-pairs, $N spheres, radius $R, $c1 touching pairs (best of $REPS)"
printf "%-28s %8s s\n" "1 cell, 1 worker" "$t1" "2x2x2 cells, 1 worker" "$t8" \
  "2x2x2 cells, 2 workers" "$t8w2" "4x4x4 cells, 1 worker" "$t64" "4x4x4 cells, 2 workers" "$t64w2"
echo "decomposition overhead 2x2x2 / 1 cell (1 worker): $(ratio "$t8" "$t1")"
echo "decomposition overhead 4x4x4 / 1 cell (1 worker): $(ratio "$t64" "$t1")"
echo "speedup 2 workers / 1 worker (2x2x2):           $(ratio "$t8" "$t8w2")"
echo "speedup 2 workers / 1 worker (4x4x4):           $(ratio "$t64" "$t64w2")"
echo "cores on this machine: $(nproc)"
