#!/bin/sh
# nff2pov.sh - bench/nff2pov.py converts concave polygons so that POV-Ray draws them as
# vwalls does: the converted scene, rendered by povray without antialiasing, covers
# exactly the pixels vwalls render's image covers (a pixel is covered when it is not
# the background colour). A fan from the first corner, which the converter used to
# emit, covers the notches of the concave polygons (239 of 4096 pixels on
# tests/data/good/concave.nff; 107 from its one concave pp polygon alone).
#   usage: nff2pov.sh VWALLS NFF2POV SCENE.nff TMPDIR   (status 77: no povray or python3)
set -u
V=$1 CONV=$2 SCENE=$3 T=$4
for x in povray python3; do
  command -v $x >/dev/null 2>&1 || { echo "skipped: no $x (scripts/setup.sh bench)"; exit 77; }
done
rm -rf "$T" && mkdir -p "$T" || exit 1
python3 "$CONV" "$SCENE" 64 64 5 >"$T/scene.pov" || { echo "FAIL: conversion"; exit 1; }
(cd "$T" && povray +I"$T/scene.pov" +O"$T/pov.ppm" +FP +W64 +H64 -D -A File_Gamma=1.0 \
   >"$T/povray.log" 2>&1) || { cat "$T/povray.log"; echo "FAIL: povray"; exit 1; }
"$V" render "$SCENE" -o "$T/vw.pfm" --size 64x64 --depth 5 --cells 1 --quiet || { echo "FAIL: render"; exit 1; }
bg=$(sed -n 's/^b \([-0-9.e]*\) \([-0-9.e]*\) \([-0-9.e]*\).*/\1,\2,\3/p' "$SCENE")
python3 "$(dirname "$0")/pov_compare.py" "$T/pov.ppm" "$T/vw.pfm" --covered "$bg"
