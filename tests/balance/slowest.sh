#!/bin/sh
# slowest.sh - a balance the render keeps never gives its slowest worker more work than
# the layout it started from: on an oblique line of spheres (bench/balance.sh's) at
# 2x2x2 cells and 160x160, a cell a worker, with the counted work as the load (ray-cell visits:
# deterministic), the most visits any worker makes with each balancer is at most what
# it is with none. rotate (a larger world box: more eye rays enter it) and divide (more
# walls, more visits) lowered lambda and were kept while their slowest worker did 2.2
# and 1.2 times the unbalanced one's work (6220 and 3345 visits against 2777).
# usage: slowest.sh VWALLS TMPDIR
set -u
V=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") T=$2
HERE=$(cd "$(dirname "$0")" && pwd)
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
awk -f "$HERE/../../bench/oblique.awk" > oblique.nff
# The most ray-cell visits of any worker in a run's stats (python3: scripts/setup.sh build).
slowest() {
  python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); print(max(w["counters"]["segments"] for w in j["workers"]))' "$1"
}
for b in none tensor rotate staggered divide duplicate; do
  "$V" render oblique.nff -o "$b.png" --size 160x160 --cells 2x2x2 --workers 8 --farm none --balance "$b" \
    --balance-load segments --stats "$b.json" --quiet 2> err.txt
  rc=$?
  [ "$rc" -eq 0 ] || { cat err.txt; fail "$b: status $rc"; }
  n=$(slowest "$b.json")
  [ -n "$n" ] || fail "$b: no per-worker segments in the stats"
  echo "$b: the slowest worker visits $n cells"
  eval "s_$b=$n"
  cmp -s none.png "$b.png" || fail "$b: the image differs from none's"
done
for b in tensor rotate staggered divide duplicate; do
  eval "n=\$s_$b"
  [ "$n" -le "$s_none" ] || fail "$b kept a layout whose slowest worker visits $n cells, $s_none with none"
done
echo ok
