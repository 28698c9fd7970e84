#!/bin/sh
# nff2pov.sh - bench/nff2pov.py converts a scene so that POV-Ray draws what vwalls does:
# the converted scene, rendered by povray without antialiasing, against vwalls render's
# image, and the conversion warns of nothing.
#  covered: the same pixels are covered (not the background colour). For concave
#    polygons: a fan from the first corner, which the converter used to emit, covers
#    their notches (239 of 4096 pixels on tests/data/good/concave.nff; 107 from its one
#    concave pp polygon alone).
#  within: every pixel within 0.02 in every channel. For the '#vw Ks' (per-channel
#    highlight) and '#vw Ke' (emission) extension lines (tests/raytrace/nff2pov_ext.nff):
#    Ke was dropped (a black sphere where vwalls draws a glowing one) and a coloured
#    highlight turned white. And what POV-Ray cannot draw (a highlight in no proportion
#    to the colour, an emission in a channel where the colour is 0) is said on stderr.
#   usage: nff2pov.sh VWALLS NFF2POV SCENE.nff TMPDIR covered|within
#   (status 77: no povray or python3)
set -u
V=$1 CONV=$2 SCENE=$3 T=$4 MODE=$5
for x in povray python3; do
  command -v $x >/dev/null 2>&1 || { echo "skipped: no $x (scripts/setup.sh bench)"; exit 77; }
done
rm -rf "$T" && mkdir -p "$T" || exit 1
fail=0
python3 "$CONV" "$SCENE" 64 64 5 >"$T/scene.pov" 2>"$T/conv.err" || { cat "$T/conv.err"; echo "FAIL: conversion"; exit 1; }
[ ! -s "$T/conv.err" ] || { echo "FAIL: the conversion warned:"; cat "$T/conv.err"; fail=1; }
(cd "$T" && povray +I"$T/scene.pov" +O"$T/pov.ppm" +FP +W64 +H64 -D -A File_Gamma=1.0 \
   >"$T/povray.log" 2>&1) || { cat "$T/povray.log"; echo "FAIL: povray"; exit 1; }
"$V" render "$SCENE" -o "$T/vw.pfm" --size 64x64 --depth 5 --cells 1 --quiet || { echo "FAIL: render"; exit 1; }
compare() { python3 "$(dirname "$0")/pov_compare.py" "$T/pov.ppm" "$T/vw.pfm" "$@" || fail=1; }
case $MODE in
covered)
  compare --covered "$(sed -n 's/^b \([-0-9.e]*\) \([-0-9.e]*\) \([-0-9.e]*\).*/\1,\2,\3/p' "$SCENE")" ;;
within)
  # 0.02: POV-Ray's 8-bit output and float differences (measured: at most 0.004).
  compare --within 0.02
  # What POV-Ray cannot draw is said, naming the material.
  cat >"$T/lossy.nff" <<'EOF'
v
from 0 -6 0
at 0 0 0
up 0 0 1
angle 40
f 1 0 0.5 0.5 0.6 30 0 1
#vw Ks 0.1 0.6 0.3
#vw Ke 0.2 0.2 0
s 0 0 0 1
EOF
  python3 "$CONV" "$T/lossy.nff" 64 64 5 >"$T/lossy.pov" 2>"$T/lossy.err" || { echo "FAIL: conversion of lossy.nff"; fail=1; }
  for want in "material 0: highlight '#vw Ks 0.1 0.6 0.3'.*mean" "material 0: emission '#vw Ke 0.2 0.2 0.0'.*channel g"; do
    grep -q "$want" "$T/lossy.err" || { echo "FAIL: no warning matching \"$want\":"; cat "$T/lossy.err"; fail=1; }
  done ;;
*) echo "usage: nff2pov.sh VWALLS NFF2POV SCENE.nff TMPDIR covered|within"; exit 2 ;;
esac
[ "$fail" = 0 ] && echo "ok"
exit $fail
