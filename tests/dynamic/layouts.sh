#!/bin/sh
# layouts.sh - the decisions (every edit's outcome in the --log) and the frames of one
# script are the same whatever the cells (1, 2x2x1, 4x4x4), the workers (1, 2) or the
# brute-force reference, on a scene made to stress the walls: a pair of spheres touching
# in the plane x = 0 (a wall of 2x2x1 and 4x4x4), a thin pane lying in that wall, a
# floor, a cone, and a polygon whose first two corners coincide (a segment: the
# sphere-triangle distance was a NaN there, so nothing ever hit it). The script moves
# objects by exactly the touching distance and a hair more, through the pane and the
# floor with sweep on, across several walls, out of the world box, rotates, adds and
# removes, then a pseudo-random tail (its own generator: the same on every awk).
# Usage: layouts.sh VWALLS WORKDIR
set -u
V=$1
W=$2
rm -rf "$W" && mkdir -p "$W" && cd "$W" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }

cat > scene.nff <<'N'
v
from 0 -20 0
at 0 0 0
up 0 0 1
angle 40
hither 0.01
resolution 16 16
b 0 0 0
l 0 -5 5
f 1 1 1 1 0 0 0 1
s -4 -4 -4 0.25
s 4 4 4 0.25
s -1 0 0 1
s 1 0 0 1
p 3
0 -3 -3
0 3 -3
0 0 3
p 4
-3 -3 -2
3 -3 -2
3 3 -2
-3 3 -2
c
2 2 -1 0.5
2 2 1 0.2
s -2 2 1 0.5
s 2 -2 1 0.1
p 3
-3 -1 1
-1 -1 1
-2 1 1
p 3
-2 3 -1.5
-2 3 -1.5
2 3 -1.5
s 0.5 2 -0.5 0.25
s -1.5 -2 2 0.5
s 1.5 1.5 2.5 0.25
s -2.5 1 -1 0.1
N
# Ids: 0, 1 the corners; 2, 3 the touching pair; 4 the pane (x = 0); 5 the floor
# (z = -2); 6 the cone; 7, 8 spheres; 9 a triangle (z = 1); 10 the segment polygon
# (y = 3, z = -1.5); 11-14 spheres.
cat > edits.txt <<'E'
move 2 0 0 0
move 3 -0.5 0 0
move 2 0 0 1e-10
moveto 11 0 3 -1.5
moveto 11 1 3 -1.3
moveto 11 1 3 -1.25
moveto 11 1 3 -1.2500001
rotate 6 0 0 1 45
sweep on
move 11 0 0 3
move 11 0 0 -3.5
move 8 -4 0 0
move 8 0 0 -2.9
move 8 0 0 -2.95
move 7 4 0 0
move 2 0 0 -1
move 9 0 0 -2.9999999
move 9 0 0 -3
move 6 -6 0 0
move 6 0 0 -0.5
move 7 0 0 -2.5
move 1 10 0 0
moveto 3 1 0 -1
add sphere 0 0 2 0.3
add sphere 1 1 -1.5 0.5
remove 4
move 8 -4 0 0
frame
E
awk 'BEGIN {
  x = 12345
  for (i = 0; i < 150; i++) {
    x = (x * 16807) % 2147483647; r = x / 2147483647
    x = (x * 16807) % 2147483647; id = 2 + int(13 * x / 2147483647)
    x = (x * 16807) % 2147483647; a = x / 2147483647
    x = (x * 16807) % 2147483647; b = x / 2147483647
    x = (x * 16807) % 2147483647; c = x / 2147483647
    if (r < 0.05) print (a < 0.5 ? "sweep on" : "sweep off")
    else if (r < 0.08) printf "add sphere %.6f %.6f %.6f %.3f\n", 6 * a - 3, 6 * b - 3, 5 * c - 2, 0.05 + 0.45 * a * b
    else if (r < 0.1) print "remove " (11 + int(4 * a))
    else if (r < 0.2) printf "rotate %d %.4f %.4f %.4f %.2f\n", id, 2 * a - 1, 2 * b - 1, 2 * c - 1 + 1e-3, 360 * a * b - 180
    else if (r < 0.3) printf "moveto %d %.6f %.6f %.6f\n", id, (a < 0.3 ? 0 : 6 * a - 3), 6 * b - 3, 5 * c - 2
    else if (r < 0.33) print "frame"
    else printf "move %d %.6f %.6f %.6f\n", id, 6 * a - 3, 6 * b - 3, 4 * c - 2
  }
  print "frame"
}' >> edits.txt

run() { # name, options
  n=$1; shift
  mkdir -p "f_$n"
  "$V" animate scene.nff edits.txt -o "f_$n/%03d.png" --size 32x32 --keep-going --quiet \
    --log "log_$n.txt" "$@" 2>/dev/null
  [ $? -eq 2 ] || fail "$n: status (the script has lines that leave the world box: 2)"
  [ -s "f_$n/000.png" ] || fail "$n: no frame"
}
run ref --cells 1 --workers 1 --brute-force
run c1w2 --cells 1 --workers 2
run c221w1 --cells 2x2x1 --workers 1
run c221w2 --cells 2x2x1 --workers 2
run c444w1 --cells 4x4x4 --workers 1
run c444w2 --cells 4x4x4 --workers 2
for n in c1w2 c221w1 c221w2 c444w1 c444w2; do
  cmp -s log_ref.txt "log_$n.txt" || { diff log_ref.txt "log_$n.txt" | head >&2; fail "$n: decisions differ"; }
  for f in f_ref/*.png; do
    cmp -s "$f" "f_$n/${f#f_ref/}" || fail "$n: frame ${f#f_ref/} differs"
  done
done
# The hand-made lines, one by one.
expect() { grep -qx "edits.txt:$1" log_ref.txt || fail "line $1 (got: $(grep "^edits.txt:${1%%:*}:" log_ref.txt))"; }
expect "1: move 2: accepted"                                       # touching stays touching
expect "2: move 3: rejected: collides at its destination with object 2"
expect "3: move 2: accepted"                                       # moving apart from a touch
expect "4: moveto 11: rejected: collides at its destination with object 10" # on the segment
expect "5: moveto 11: rejected: collides at its destination with object 10" # 0.05 into it
expect "6: moveto 11: accepted"                                    # touching it from above
expect "7: moveto 11: rejected: collides at its destination with object 10" # 1e-7 into it
expect "10: move 11: accepted"                                     # lifted off it
expect "11: move 11: rejected: would pass through object 10"       # through the segment
expect "12: move 8: accepted"
expect "14: move 8: rejected: would pass through object 5"         # through the floor
expect "17: move 9: rejected: would pass through object 2"
expect "18: move 9: rejected: collides at its destination with object 5" # coplanar on the floor
expect "19: move 6: rejected: would pass through object 4"         # the cone through the pane
expect "22: move: invalid: object 1 would leave the world box (which cannot grow)"
expect "26: remove 4: accepted"
echo "layouts: $(grep -c accepted log_ref.txt) accepted, $(grep -c rejected log_ref.txt) rejected, the same on every layout"
