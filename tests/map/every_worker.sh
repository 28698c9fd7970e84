#!/bin/sh
# every_worker.sh - under mpirun, 3 processes of 3 workers and 2x5x1 cells with --map
# block: every one of the 9 workers hosts a cell (10 cells are enough), and the image is
# the threads engine's. The process blocks were 4, 4 and 2 cells and worker 8 had none.
# usage: every_worker.sh VWALLS TMPDIR "MPIRUN -np 3 FLAGS"
set -u
V=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") T=$2 RUN=$3
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$V" gen spheres --count 300 --cluster 0.5 -o s.nff || fail "gen"
"$V" render s.nff -o t.png --size 32x32 --cells 2x5x1 --workers 9 --farm none -q || fail "threads"
# shellcheck disable=SC2086
$RUN "$V" render s.nff -o m.png --size 32x32 --cells 2x5x1 --workers 3 --map block \
  --farm none --stats m.json -q || fail "mpirun: status $?"
cmp -s t.png m.png || fail "the image differs from the threads engine's"
hosts=$(python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); print(" ".join(str(sum(c["worker"] == w for c in j["cells"])) for w in range(9)))' m.json)
echo "cells a worker: $hosts"
for n in $hosts; do [ "$n" -ge 1 ] || fail "a worker hosts no cell ($hosts)"; done
echo "ok"
