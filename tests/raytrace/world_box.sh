#!/bin/sh
# world_box.sh VWALLS TMPDIR - `vwalls render --world` (and animate's, edit's, bench's): the world
# box covers the box given, so the walls divide the space the scene is meant to fill,
# not only its objects' bounds.
# A fully clustered sphere scene (`vwalls gen spheres`: its cluster lies in one octant of
# the cube [0,10]^3) then has every object in one cell of 2x2x2, as the paper's clustered
# load case means (without --world the walls cut the cluster's own box evenly); the image
# is the same on every layout; a bad box is refused with exit 2 and no output.
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$V" gen spheres --count 300 --cluster 1 --seed 1 -o c1.nff || fail "gen"
# nonempty FILE: how many cells of the stats hold objects
nonempty() { grep '"box": ' "$1" | grep -c '"objects": [1-9]'; }
r() { n=$1; shift; "$V" render c1.nff -o "$n.png" --size 64x48 --quiet --stats "$n.json" "$@" ||
  fail "$n: status $?"; }
r one --cells 1 --world 0,0,0,10,10,10
r w8 --cells 2x2x2 --workers 2 --world 0,0,0,10,10,10
r w24 --cells 2x4 --workers 2 --farm none --world 0,0,0,10,10,10
r free8 --cells 2x2x2 --workers 2
for n in w8 w24 free8; do cmp -s one.png "$n.png" || fail "$n: the image differs from one cell's"; done
[ "$(nonempty w8.json)" = 1 ] || fail "--world: $(nonempty w8.json) cells of 2x2x2 hold objects, want 1"
grep -q '"box": \[\[0,0,0\],\[5,5,5\]\], "worker": [0-9]*, "objects": 300,' w8.json ||
  fail "--world: cell [0,5]^3 does not hold the 300 spheres: $(grep '"box"' w8.json | head -2)"
[ "$(nonempty free8.json)" -ge 4 ] || fail "no --world: only $(nonempty free8.json) cells hold objects"
# A box smaller than the scene: the world box still covers the scene (same image).
r small --cells 2x2x2 --world 2,2,2,3,3,3
cmp -s one.png small.png || fail "a --world inside the scene changed the image"
for bad in "0,0,0,10,10" "0,0,0,10,10,x" "0,0,0,10,-1,10" "0,0,0,0,10,10" "0,0,0,nan,10,10"; do
  "$V" render c1.nff -o bad.png --size 16x16 --world "$bad" 2>err.txt; rc=$?
  [ $rc -eq 2 ] || fail "--world $bad: exit $rc"
  grep -q "vwalls render: --world: bad value '$bad'" err.txt || fail "--world $bad: $(cat err.txt)"
  [ ! -e bad.png ] || fail "--world $bad: output written"
done
# animate and edit take the same box (rt_anim_params.world_min): one frame on 2x2x2.
printf 'frame\n' > frame.txt
"$V" animate c1.nff frame.txt -o 'an%d.png' --cells 2x2x2 --size 32x24 --quiet --stats an.json \
  --world 0,0,0,10,10,10 || fail "animate --world: status $?"
grep -q '"box": \[\[0,0,0\],\[5,5,5\]\], "worker": [0-9]*, "objects": 300,' an.json ||
  fail "animate --world: cell [0,5]^3 does not hold the 300 spheres: $(grep '"box"' an.json | head -2)"
printf 'frame\n' | "$V" edit c1.nff -o 'ed%d.png' --cells 2x2x2 --size 32x24 --quiet \
  --stats ed.json --world 0,0,0,10,10,10 > /dev/null || fail "edit --world: status $?"
grep -q '"box": \[\[0,0,0\],\[5,5,5\]\], "worker": [0-9]*, "objects": 300,' ed.json ||
  fail "edit --world: cell [0,5]^3 does not hold the 300 spheres"
"$V" animate c1.nff frame.txt -o 'bad%d.png' --world 0,0,0,10,10 2>err.txt; rc=$?
[ $rc -eq 2 ] || fail "animate --world 0,0,0,10,10: exit $rc"
grep -q "vwalls animate: --world: bad value '0,0,0,10,10'" err.txt || fail "animate: $(cat err.txt)"
[ ! -e bad0.png ] || fail "animate --world bad: output written"
# bench takes it too: its 2x2x2 row visits as many ray-cell segments as render's 2x2x2
# on the same box (a deterministic count), and a bad box is refused.
segs() { sed -n 's/.*"segments": \([0-9]*\).*/\1/p' "$1" | head -1; }
r seg8 --cells 2x2x2 --workers 1 --world 0,0,0,10,10,10
b() { n=$1; shift; "$V" bench c1.nff --cells 2x2x2 --workers 1 --repeat 1 --size 64x48 --quiet \
  --stats "$n.json" "$@" > /dev/null || fail "bench $n: status $?"; }
b bw --world 0,0,0,10,10,10
b bfree
grep -q '"world": \[\[0, 0, 0\], \[10, 10, 10\]\]' bw.json || fail "bench --world: not in its stats"
grep -q '"world": null' bfree.json || fail "bench without --world: no \"world\": null"
[ "$(segs bw.json)" = "$(segs seg8.json)" ] ||
  fail "bench --world: $(segs bw.json) segments, render's $(segs seg8.json)"
[ "$(segs bfree.json)" != "$(segs seg8.json)" ] || fail "bench without --world: the box was used"
"$V" bench c1.nff --world 0,0,0,10,10 --stats bad.json 2>err.txt; rc=$?
[ $rc -eq 2 ] || fail "bench --world 0,0,0,10,10: exit $rc"
grep -q "vwalls bench: --world: bad value '0,0,0,10,10'" err.txt || fail "bench: $(cat err.txt)"
[ ! -e bad.json ] || fail "bench --world bad: output written"
echo ok
