#!/bin/sh
# anim_inputs.sh - the frames of vwalls animate / edit against the inputs, and a frame
# vwalls edit cannot write.
#  * A frame that would replace an input (the script, the scene through a link, an OBJ's
#    material library through a link) is status 2 before any frame, the input intact
#    (the script e1.png was replaced by frame 1 of -o 'e%d.png', the scene by a frame
#    name linked to it).
#  * vwalls edit goes on after a frame it cannot write (its directory removed): the
#    message, the next 'frame' writes that number, the later edits are applied, status 1
#    (the session used to end there, the lines after it unread).
# Usage: anim_inputs.sh VWALLS WORKDIR
set -u
V=$1
W=$2
rm -rf "$W" && mkdir -p "$W" && cd "$W" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }

"$V" gen spheres --count 30 --seed 3 --resolution 16x16 -o scene.nff || fail "gen"
cp scene.nff scene.orig

# The script is frame 1 of the pattern.
printf 'frame\nframe\n' > e1.png
cp e1.png e1.orig
"$V" animate scene.nff e1.png -o 'e%d.png' --quiet 2> err.txt; rc=$?
[ $rc -eq 2 ] || fail "script as frame 1: status $rc, expected 2"
grep -qx "vwalls animate: -o e%d.png: frame 1 is the input file e1.png: it would be overwritten" err.txt ||
  fail "script as frame 1: message: $(cat err.txt)"
cmp -s e1.png e1.orig || fail "script as frame 1: the script was replaced"
[ -e e0.png ] && fail "script as frame 1: frame 0 was written"

# A frame name that links to the scene, at a number no input's name holds (3).
printf 'frame\nframe\nframe\nframe\n' > four.txt
ln -s scene.nff lk3.png
"$V" animate scene.nff four.txt -o 'lk%d.png' --quiet 2> err.txt; rc=$?
[ $rc -eq 2 ] || fail "frame 3 linked to the scene: status $rc, expected 2"
grep -qx "vwalls animate: -o lk%d.png: frame 3 is the input file scene.nff: it would be overwritten" err.txt ||
  fail "frame 3 linked to the scene: message: $(cat err.txt)"
cmp -s scene.nff scene.orig || fail "frame 3 linked to the scene: the scene was replaced"
[ -e lk0.png ] && fail "frame 3 linked to the scene: frame 0 was written"
# Three frames do not reach it.
printf 'frame\nframe\nframe\n' > three.txt
"$V" animate scene.nff three.txt -o 'lk%d.png' --quiet || fail "three frames, the fourth linked: status $?"
[ -s lk2.png ] && cmp -s scene.nff scene.orig || fail "three frames, the fourth linked: frames or scene"

# --stats and --log against every frame the script writes, whatever their names say: a
# link (symbolic or hard) to frame 3 of a run before, named otherwise, and a name that
# holds another frame's number (they were checked at the number their name holds only).
printf 'frame\nframe\nframe\nframe\nframe\n' > five.txt
"$V" animate scene.nff five.txt -o 'pf%04d.png' --quiet || fail "five frames: status $?"
cp pf0003.png pf3.orig
ln -s pf0003.png sl.json
ln pf0003.png hl.log
ln -s pf0002.png sl0007.json
for opt in "--stats sl.json" "--log hl.log" "--stats sl0007.json"; do
  rm -f pf0000.png
  # shellcheck disable=SC2086
  "$V" animate scene.nff five.txt -o 'pf%04d.png' --quiet $opt 2> err.txt; rc=$?
  [ $rc -eq 2 ] || fail "$opt, a link to a frame: status $rc, expected 2"
  grep -q "^vwalls animate: $opt: frame [23] of -o pf%04d.png: one would overwrite the other$" err.txt ||
    fail "$opt, a link to a frame: message: $(cat err.txt)"
  [ -e pf0000.png ] && fail "$opt, a link to a frame: frame 0 was written"
  cmp -s pf0003.png pf3.orig || fail "$opt: frame 3 changed"
done
# Four frames do not reach frame 4; a link to frame 4 is no frame of theirs.
ln -s pf0004.png sfour.json
"$V" animate scene.nff four.txt -o 'pf%04d.png' --quiet --stats sfour.json || fail "four frames, --stats a link to frame 4: status $?"

# vwalls edit: the frame number an input's name holds (its frames are not known ahead).
ln -s scene.nff ed0.png
echo frame | "$V" edit scene.nff -o 'ed%d.png' --quiet > /dev/null 2> err.txt; rc=$?
[ $rc -eq 2 ] || fail "edit, frame 0 linked to the scene: status $rc, expected 2"
grep -qx "vwalls edit: -o ed%d.png: frame 0 is the input file scene.nff: it would be overwritten" err.txt ||
  fail "edit, frame 0 linked to the scene: message: $(cat err.txt)"
cmp -s scene.nff scene.orig || fail "edit: the scene was replaced"

# An OBJ's material library.
cat > m.mtl <<'E'
newmtl red
Kd 1 0 0
E
cat > m.obj <<'E'
mtllib m.mtl
usemtl red
v -1 0 0
v 1 0 0
v 0 0 1
f 1 2 3
E
cp m.mtl m.orig
ln -s m.mtl o1.png
"$V" animate m.obj three.txt -o 'o%d.png' --size 8x8 --quiet 2> err.txt; rc=$?
[ $rc -eq 2 ] || fail "frame 1 linked to the material library: status $rc, expected 2"
grep -q "frame 1 is the input file .*m.mtl: it would be overwritten" err.txt ||
  fail "frame 1 linked to the material library: message: $(cat err.txt)"
cmp -s m.mtl m.orig || fail "the material library was replaced"

# vwalls edit goes on after a frame it cannot write.
mkdir fd
rm -f err.txt
{
  echo frame
  # the directory goes away before the second frame, and comes back before the third
  n=0
  while [ ! -s fd/0.png ] && [ $n -lt 300 ]; do sleep 0.1; n=$((n + 1)); done
  rm -rf fd
  echo 'remove 1'
  echo frame
  n=0
  while ! grep -q 'cannot create' err.txt 2> /dev/null && [ $n -lt 300 ]; do sleep 0.1; n=$((n + 1)); done
  mkdir fd
  echo 'remove 2'
  echo frame
} | "$V" edit scene.nff -o 'fd/%d.png' --workers 1 --log fd.log --stats fd.json > out.txt 2> err.txt
rc=$?
[ $rc -eq 1 ] || fail "edit, a frame not written: status $rc, expected 1; $(cat err.txt)"
grep -qx "vwalls edit: fd/1.png: cannot create: No such file or directory" err.txt ||
  fail "edit, a frame not written: message: $(cat err.txt)"
[ -s fd/1.png ] && [ ! -e fd/2.png ] || fail "edit: the frame after the failed one is not number 1: $(ls fd)"
grep -q '^remove 2: accepted$' out.txt || fail "edit: the lines after the failed frame were not read: $(cat out.txt)"
grep -q '2 accepted.*; 2 frames' out.txt || fail "edit: summary: $(tail -1 out.txt)"
python3 - fd.json <<'PY' || fail "edit: the stats' frames"
import json, sys
a = json.load(open(sys.argv[1]))["animation"]
assert [f["frame"] for f in a["per_frame"]] == [0, 1], a
assert a["per_frame"][1]["accepted"] == 2, a
PY
echo "anim_inputs ok"
