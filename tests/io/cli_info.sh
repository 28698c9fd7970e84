#!/bin/sh
# cli_info.sh VWALLS TMPDIR - vwalls info --materials: one line per material with its
# name, where it was defined (FILE:LINE) and how many objects use it, and a warning line
# for each reflectance the radiosity solver clamps or warns about. An OBJ with two
# libraries (one in a subdirectory; a material without Kd, so its newmtl line; an
# emitter of Kd 1, not flagged; an unused one whose name has a quote, a control byte
# and more than 40 bytes; a usemtl name no library defines), and an NFF whose equal
# 'f' lines share one material (the first f's line).
set -u
V=$1 T=$2
rm -rf "$T" && mkdir -p "$T/lib" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
# has FILE LINE: FILE holds LINE, whole.
has() { grep -Fqx -e "$2" "$1" || { cat "$1"; fail "$1 lacks: $2"; }; }

printf '# the first library\nnewmtl red\nNs 10\nKd 1.25 0 0\nnewmtl grey\nNs 10\n' > lib/a.mtl
printf 'newmtl white\nKd 1 1 1\nnewmtl lamp\nKd 1 1 1\nKe 5 5 5\n' > b.mtl
printf "newmtl it's\\351odd and a name longer than forty bytes\\nKd 0.5 0.5 0.5\\n" >> b.mtl
cat > s.obj <<'END'
# two libraries
mtllib lib/a.mtl
mtllib b.mtl
v 0 0 0
v 1 0 0
v 0 1 0
f 1 2 3
usemtl red
f 1 2 3
f 1 3 2
usemtl grey
f 1 2 3
usemtl white
f 1 2 3
usemtl lamp
f 1 2 3
usemtl missing
f 1 2 3
END
"$V" info s.obj --materials > out 2> err || fail "info s.obj --materials: status $? ($(cat err))"
has out "materials: 7"
has out "material 0: 'red' at ./lib/a.mtl:4 used by 2 (diffuse 1.25 0 0, specular 0 0 0, reflect 0 0 0, shine 10, transmit 0, ior 1, emission 0 0 0)"
has out "./lib/a.mtl:4: warning: material 'red': reflectance 1.25 0 0 is outside [0, 1]: the radiosity solver clamps it"
has out "./lib/a.mtl:4: warning: material 'red': reflectance 1.25 0 0 is 1 or more in a channel, so it absorbs nothing there: a closed scene's radiosity solve may be slow or stall"
has out "material 1: 'grey' at ./lib/a.mtl:5 used by 1 (diffuse 0.8 0.8 0.8, specular 0 0 0, reflect 0 0 0, shine 10, transmit 0, ior 1, emission 0 0 0)"
has out "material 2: 'white' at ./b.mtl:2 used by 1 (diffuse 1 1 1, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 0 0 0)"
has out "./b.mtl:2: warning: material 'white': reflectance 1 1 1 is 1 or more in a channel, so it absorbs nothing there: a closed scene's radiosity solve may be slow or stall"
has out "material 3: 'lamp' at ./b.mtl:4 used by 1 (diffuse 1 1 1, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 5 5 5)"
has out "material 4: 'it?s?odd and a name longer than forty by...' at ./b.mtl:7 used by 0 (diffuse 0.5 0.5 0.5, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 0 0 0)"
has out "material 5: at - used by 1 (diffuse 0.8 0.8 0.8, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 0 0 0)"
has out "material 6: 'missing' at - used by 1 (diffuse 0.8 0.8 0.8, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 0 0 0)"
[ "$(grep -c '^material ' out)" -eq 7 ] || fail "s.obj: not 7 material lines: $(cat out)"
[ "$(grep -c ': warning: ' out)" -eq 3 ] || fail "s.obj: not 3 warnings: $(cat out)"
# The reader's warning stays on stderr, once.
has err "s.obj:17: warning: material 'missing' is not defined by a material library (the default material is used)"
[ "$(wc -l < err)" -eq 1 ] || fail "s.obj: stderr: $(cat err)"
# Without the option, no material lines (the description is as it was).
"$V" info s.obj > plain 2> /dev/null || fail "info s.obj: status $?"
! grep -q '^material \|warning' plain || fail "info s.obj: material lines without --materials: $(cat plain)"

cat > s.nff <<'END'
v
from 0 -5 0
at 0 0 0
up 0 0 1
angle 40
hither 0.1
resolution 8 8
b 0 0 0
l 0 0 5
f 1 1 1 1 0 0 0 1
s 0 0 0 1
s 2 0 0 1
f 0.5 0.5 0.5 0.5 0 0 0 1
c 0 0 0 1 0 0 1 1
f 1 1 1 1 0 0 0 1
p 3
0 0 0
1 0 0
0 1 0
f 1 0.5 0.5 2 0 0 0 1
s 5 5 5 1
END
"$V" info s.nff --objects --materials > out 2> err || fail "info s.nff --materials: status $? ($(cat err))"
[ ! -s err ] || fail "s.nff: stderr: $(cat err)"
has out "material 0: at s.nff:10 used by 3 (diffuse 1 1 1, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 0 0 0)"
has out "s.nff:10: warning: material 0: reflectance 1 1 1 is 1 or more in a channel, so it absorbs nothing there: a closed scene's radiosity solve may be slow or stall"
has out "material 1: at s.nff:13 used by 1 (diffuse 0.25 0.25 0.25, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 0 0 0)"
has out "material 2: at s.nff:20 used by 1 (diffuse 2 1 1, specular 0 0 0, reflect 0 0 0, shine 0, transmit 0, ior 1, emission 0 0 0)"
has out "s.nff:20: warning: material 2: reflectance 2 1 1 is outside [0, 1]: the radiosity solver clamps it"
has out "s.nff:20: warning: material 2: reflectance 2 1 1 is 1 or more in a channel, so it absorbs nothing there: a closed scene's radiosity solve may be slow or stall"
[ "$(grep -c '^material ' out)" -eq 3 ] || fail "s.nff: not 3 material lines: $(cat out)"
[ "$(grep -c ': warning: ' out)" -eq 3 ] || fail "s.nff: not 3 warnings: $(cat out)"
# --objects names the same numbers: the polygon uses material 0, the last sphere 2.
grep -q '^3 polygon 3 vertices .* material 0 ' out || fail "s.nff: polygon's material: $(cat out)"
grep -q '^4 sphere .* material 2 ' out || fail "s.nff: last sphere's material: $(cat out)"
echo "ok"
