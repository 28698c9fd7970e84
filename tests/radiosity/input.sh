#!/bin/sh
# input.sh VWALLS TMPDIR TEST_RADIOSITY - what `vwalls radiosity` says about a scene it
# cannot solve as given, and pictures that depend on the scene's scale or on rounding:
#  - spheres and cones are meshed as facets: they block, receive and emit light (they
#    were silently left out), and the CSV reports each; a PLY scene's refusal says PLY
#    has no emission;
#  - a mesh warning names the line of its polygon when NFF puts two polygons on one
#    line or ends lines with a lone CR (physical lines were scanned for a leading 'p');
#  - --patch-size above the polygons' size keeps one element a polygon (it kept none:
#    0 elements, "converged", exit 0);
#  - --view's near plane follows the scene's size (a scene 5.6e-5 across was black),
#    and a view 1e-10 off vertical is the vertical view's picture (it was turned).
set -u
V=$1 T=$2 TR=$3
rm -rf "$T" && mkdir -p "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$TR" gen cornell "$T/cornell.nff" || fail "gen"

# A grey floor, a sphere and a cone; the light is the emitting quad, or the sphere.
head='v
from 0.5 0.5 -2
at 0.5 0.5 0.5
up 0 1 0
angle 45
hither 0.01
resolution 16 16
f 0.7 0.7 0.7 1 0 0 0 1
p 4
0 0 0
0 0 1
1 0 1
1 0 0'
light='f 1 1 1 1 0 0 0 1
#vw Ke 5 5 5'
quad='p 4
0.4 1 0.4
0.6 1 0.4
0.6 1 0.6
0.4 1 0.6'
printf '%s\n%s\n%s\ns 0.5 0.3 0.5 0.1\nc 0 0.5 0 0.1 1 0.5 0 0.1\ns 0.2 0.3 0.5 0.1\n' "$head" "$light" "$quad" \
  >"$T/curved.nff"
"$V" radiosity "$T/curved.nff" -o "$T/c.ply" --csv "$T/c.csv" --sf 0.01 --workers 1 --quiet 2>"$T/err" \
  || fail "curved: $(cat "$T/err")"
[ ! -s "$T/err" ] || fail "curved: a message: $(cat "$T/err")"
# Ids 2 and 4 are the spheres (16 x 8 facets: 96.8 % of 4 pi r^2), 3 the cylinder (16
# facets: 99.4 % of 2 pi r h); all emit, and each gets one CSV row.
for want in '2,0.12166' '4,0.12166' '3,0.62428'; do
  grep -q "^$want[0-9]*,1,1,1,5,5,5," "$T/c.csv" || fail "curved: no CSV row $want: $(cat "$T/c.csv")"
done
# Too many spheres for the facets: refused before they are made (exit 2).
{ printf '%s\n%s\n' "$head" "$light"; awk 'BEGIN { for (i = 0; i < 16385; i++) print "s", i, 2, 0, 0.4 }'; } \
  >"$T/many.nff"
"$V" radiosity "$T/many.nff" -o "$T/m.ply" --quiet 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "many.nff: 16385 spheres and 0 cones are 2097280 facets" "$T/err" \
  || fail "16385 spheres: exit $rc, $(cat "$T/err")"
[ ! -e "$T/m.ply" ] || fail "16385 spheres: output written"
# A sphere alone lights the floor under it.
printf '%s\n%s\ns 0.5 0.5 0.5 0.1\n' "$head" "$light" >"$T/sphlight.nff"
"$V" radiosity "$T/sphlight.nff" --csv "$T/s.csv" --sf 0.01 --workers 1 --quiet 2>"$T/err" \
  || fail "sphere light: $(cat "$T/err")"
awk -F, '$1 == 0 && $9 > 0.01 { lit = 1 } $1 == 1 && $6 == 5 { sphere = 1 } END { exit !(lit && sphere) }' \
  "$T/s.csv" || fail "sphere light: $(cat "$T/s.csv")"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' \
  >"$T/tri.ply"
"$V" radiosity "$T/tri.ply" -o "$T/t.ply" --quiet 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "tri.ply: no emitter: .*PLY has no emission: convert the scene to OBJ+MTL or NFF" "$T/err" \
  || fail "PLY: exit $rc, $(cat "$T/err")"

# The non-planar polygon (id 2) is the third 'p', on line 12; the first two share line 10.
printf '%s\n' "$head" | sed -n 1,7p >"$T/two.nff"
printf '%s\n' 'f 1 1 1 1 0 0 0 1' '#vw Ke 5 5 5' \
  'p 4 0.4 1 0.4 0.6 1 0.4 0.6 1 0.6 0.4 1 0.6 f 0.7 0.7 0.7 1 0 0 0 1 p 4 0 0 0 0 0 1 1 0 1 1 0 0' \
  'f 0.5 0.5 0.5 1 0 0 0 1' 'p 4 0 0 0.2 1 0 0.2 1 1 0.2 0 1 0.21' >>"$T/two.nff"
for ends in lf cr; do
  f=$T/two_$ends.nff
  if [ $ends = cr ]; then tr '\n' '\r' <"$T/two.nff" >"$f"; else cp "$T/two.nff" "$f"; fi
  "$V" radiosity "$f" -o "$T/w.ply" --max-shots 4 --quiet 2>"$T/err" || fail "two a line ($ends): $(cat "$T/err")"
  grep -q "two_$ends.nff:12: warning: polygon (id 2) is not planar" "$T/err" \
    || fail "two a line ($ends): $(cat "$T/err"); file: $(cat -A "$f")"
done

"$V" radiosity "$T/cornell.nff" -o "$T/big.ply" --patch-size 1e30 --cells 1 --workers 1 \
  --stats "$T/big.json" --quiet \
  || fail "--patch-size 1e30: exit $?"
# One cell: one piece and one element per polygon, or per convex part of one (22).
grep -q '"shots": [1-9][0-9]*, .*"pieces": 22, "elements": 22,' "$T/big.json" \
  || fail "--patch-size 1e30: $(grep -o '"radiosity": {[^}]*}' "$T/big.json")"

# The Cornell box scaled to 5.6e-5 across, seen from its own camera's place.
awk -v s=1e-7 '
/^(from|at|l) / { printf "%s %.17g %.17g %.17g", $1, $2 * s, $3 * s, $4 * s; for (i = 5; i <= NF; i++) printf " %s", $i; print ""; next }
/^hither / { print "hither", $2 * s; next }
/^[-0-9.]/ { for (i = 1; i <= NF; i++) $i = sprintf("%.17g", $i * s); print; next }
{ print }' "$T/cornell.nff" >"$T/tiny.nff"
"$V" radiosity "$T/tiny.nff" --image "$T/tiny.pfm" --size 32x32 --view 2.78e-5,2.73e-5,-8e-5,2.78e-5,2.73e-5,0,40 \
  --sf 0.01 --workers 1 --quiet || fail "tiny scene: exit $?"
"$TR" pfmcmp "$T/tiny.pfm" "$T/tiny.pfm" 0.5 0 || fail "tiny scene: the picture is not lit"
"$V" radiosity "$T/cornell.nff" --image "$T/vert.pfm" --size 32x32 --view 278,540,279,278,0,279,90 \
  --sf 0.01 --workers 1 --quiet || fail "vertical view: exit $?"
"$V" radiosity "$T/cornell.nff" --image "$T/near.pfm" --size 32x32 --view 278,540,279,278.0000001,0,279,90 \
  --sf 0.01 --workers 1 --quiet || fail "near vertical view: exit $?"
"$TR" pfmcmp "$T/vert.pfm" "$T/near.pfm" 0.5 0.001 || fail "a view 1e-10 off vertical is another picture"
echo "ok"
