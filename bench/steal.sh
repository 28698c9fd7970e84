#!/usr/bin/env bash
# bench/steal.sh - farmed copies on two processes taking each other's turns (--steal,
# docs/runtime.md "Farmed work"): one cell, its master on process 0 and its copy on
# process 1 (mpirun -np 2, one worker each), the second process's worker slowed K times
# (--slow 1:K) with the speeds not given (--speeds 1,1: the shares stay equal) and
# given (the shares follow them). --steal off against on, interleaved, ROUNDS rounds:
# the medians of the compute phase and of the busy-time lambda, and off/on. With one
# worker a process there is nothing to take within a process, so off is the code
# before turns crossed processes.
# Usage: bench/steal.sh [ROUNDS] [SIZE] [BIND]; BIND is Open MPI's --bind-to (default
# core, its default for -np 2: a worker and its communication thread share one core);
# VW_BUILD_DIR picks the build.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
ROUNDS=${1:-5}
SIZE=${2:-512x512}
BIND=${3:-core}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$VWALLS" gen balls -o "$T/balls.nff"
launch=(mpiexec -n 2)
if mpiexec --version 2>/dev/null | grep -q "Open MPI"; then
  launch+=(--oversubscribe --bind-to "$BIND")
else
  launch+=(-bind-to "$BIND")
fi
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(' '.join(str(eval('d'+k)) for k in sys.argv[2:]))" "$@"; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2) }'; }

echo "one cell on 2 processes x 1 worker, $SIZE, binding $BIND, medians of $ROUNDS interleaved rounds"
echo "| process 1 | speeds | steal | compute s | lambda | off/on compute |"
echo "|---|---|---|---|---|---|"
for k in 1 3; do
  for given in no yes; do
    speeds=(--speeds 1,1)
    [ "$given" = yes ] && speeds=()
    for r in $(seq "$ROUNDS"); do
      for steal in off on; do
        "${launch[@]}" "$VWALLS" render "$T/balls.nff" -o "$T/img.png" --size "$SIZE" --cells 1 \
          --workers 1 --slow "1:$k" "${speeds[@]}" --steal "$steal" --quiet --stats "$T/s.json"
        json "$T/s.json" "['time_s']['compute']" "['balance']['imbalance']" >> "$T/$k-$given-$steal"
      done
    done
    declare -A c=() l=()
    for steal in off on; do
      c[$steal]=$(awk '{print $1}' "$T/$k-$given-$steal" | median)
      l[$steal]=$(awk '{print $2}' "$T/$k-$given-$steal" | median)
    done
    for steal in off on; do
      extra=""
      [ "$steal" = on ] && extra=$(ratio "${c[off]}" "${c[on]}")
      echo "| $([ "$k" = 1 ] && echo as fast || echo "${k}x slower") | $([ "$given" = yes ] && echo given || echo "not given") | $steal | ${c[$steal]} | ${l[$steal]} | $extra |"
    done
    [ "$k" = 1 ] && break # equal speeds: given or not is the same run
  done
done
