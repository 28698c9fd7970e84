#!/bin/sh
# embree_raw.sh - bench/embree_raw.c's line must carry its trace time precisely enough
# that rays / time gives back the rate it prints: bench/raytrace.sh and
# bench/experiments/peers.sh divide the two, and a time printed to the millisecond made
# their Embree rates and ratios wrong by tens of per cent on small images.
#   usage: embree_raw.sh VW_BENCH_EMBREE_RAW SCENE
set -u
out=$("$1" "$2" 32x32 3) || { echo "FAIL: $1 status $?"; exit 1; }
echo "$out"
t=$(echo "$out" | sed -n 's/.*trace \([0-9.]*\) s.*/\1/p')
n=$(echo "$out" | sed -n 's/.*rays \([0-9]*\),.*/\1/p')
r=$(echo "$out" | sed -n 's/.* \([0-9.]*\) Mrays\/s.*/\1/p')
[ -n "$t" ] && [ -n "$n" ] && [ -n "$r" ] || { echo "FAIL: cannot read trace, rays, rate"; exit 1; }
# The rate is printed to 0.001 Mrays/s; the time's own rounding is allowed 1 %.
awk -v t="$t" -v n="$n" -v r="$r" 'BEGIN {
  if (!(t > 0)) { print "FAIL: trace time " t " s"; exit 1 }
  d = n / t * 1e-6 - r; if (d < 0) d = -d
  if (d > 0.01 * r + 0.0005) { printf "FAIL: %d rays / %s s = %.3f Mrays/s, printed %s\n", n, t, n / t * 1e-6, r; exit 1 }
  print "ok: rays / time agrees with the printed rate" }'
