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
python3 - "$T/pov.ppm" "$T/vw.pfm" "$bg" <<'PY'
import struct, sys

def header(d, n):
    """The first n header tokens of a PPM or PFM ('#' comments skipped) and the offset
    after the single blank that ends the header."""
    toks, i = [], 0
    while len(toks) < n:
        if d[i:i + 1] == b'#':
            i = d.index(b'\n', i) + 1
        elif d[i:i + 1].isspace():
            i += 1
        else:
            j = i
            while not d[j:j + 1].isspace():
                j += 1
            toks.append(d[i:j])
            i = j
    return toks, i + 1

d = open(sys.argv[1], 'rb').read()
(magic, w, h, mx), at = header(d, 4)
assert magic == b'P6' and int(mx) == 255, magic
w, h = int(w), int(h)
pov = [[tuple(d[at + 3 * (y * w + x) + k] / 255 for k in range(3)) for x in range(w)] for y in range(h)]
d = open(sys.argv[2], 'rb').read()
(magic, w2, h2, scale), at = header(d, 4)
assert magic == b'PF' and (int(w2), int(h2)) == (w, h), magic
v = struct.unpack(('<' if float(scale) < 0 else '>') + '%df' % (3 * w * h), d[at:at + 12 * w * h])
vw = [[tuple(v[3 * (y * w + x) + k] for k in range(3)) for x in range(w)] for y in range(h)][::-1]
bg = [float(x) for x in sys.argv[3].split(',')]

def covered(c):
    return any(abs(c[k] - bg[k]) > 0.02 for k in range(3))

diff = [(x, y) for y in range(h) for x in range(w) if covered(pov[y][x]) != covered(vw[y][x])]
n = sum(covered(vw[y][x]) for y in range(h) for x in range(w))
print('%d of %d pixels covered by vwalls; %d differ in POV-Ray' % (n, w * h, len(diff)))
if diff:
    for y in range(h):  # X: differs, #: covered, .: background (vwalls)
        print(''.join('X' if (x, y) in diff else '#' if covered(vw[y][x]) else '.' for x in range(w)))
sys.exit(1 if diff else 0)
PY
