#!/bin/sh
# closed.sh VWALLS SRCDIR TMPDIR - a closed scene that reflects everything (every face Kd
# 1) absorbs nothing and lets nothing escape, so the unshot power only spreads and the
# largest patch's share never falls below --sf: the solve ran to --max-shots, or for
# ever without it, and said nothing. Now:
#  - the mesher warns before the solve, naming the first such polygon's file:line
#    (lights are not counted: a Kd 1 light among grey walls is no risk);
#  - the solve stops, stalled, when --stall-shots shots (default 10000) absorb or let
#    escape less than sf of the emitted power, with a warning, "stalled": true in the
#    stats, exit 0 and the outputs; on 1, 2x2x2 and 6x6x6 cells alike, within a round;
#  - the ledger stays balanced (nothing absorbed, all of it unshot);
#  - a box that absorbs (Kd 0.9) or is open converges as before, the rule changing
#    nothing of its solution; Kd 1 in one channel stalls on that channel's third.
# Every run has --max-shots 30000 (and a timeout where there is one): the old code
# reached it instead of stalling, and the first check below fails on it.
set -u
V=$1 SRC=$2 T=$3
rm -rf "$T" && mkdir -p "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
TO=""
command -v timeout >/dev/null 2>&1 && TO="timeout 120"
cp "$SRC/closed_box.obj" "$SRC/closed_white.mtl" "$T/" || fail "copy"
# Small and coarse, so that 10000 shots take a second: 27 patches on one cell.
fast="--patch-size 0.5 --hemicube 16 --workers 1 --max-shots 30000"

# The number after "name" in the stats' radiosity object.
field() { sed -n "s/.*\"radiosity\": {[^}]*\"$2\": \([-0-9.e+a-z]*\).*/\1/p" "$1"; }

for c in 1 2x2x2 6x6x6; do
  tag=$(echo $c | tr x _)
  $TO "$V" radiosity "$T/closed_box.obj" $fast --cells $c --stats "$T/$tag.json" \
    --csv "$T/$tag.csv" --quiet 2>"$T/$tag.err" || fail "--cells $c: exit $? ($(cat "$T/$tag.err"))"
  shots=$(field "$T/$tag.json" shots) stalled=$(field "$T/$tag.json" stalled)
  conv=$(field "$T/$tag.json" converged) err=$(field "$T/$tag.json" energy_error)
  u=$(field "$T/$tag.json" unshot) e=$(field "$T/$tag.json" emitted) a=$(field "$T/$tag.json" absorbed)
  echo "cells $c: $shots shots, stalled $stalled, converged $conv, energy error $err, unshot $u of $e"
  [ -n "$shots" ] && [ "$shots" -lt 30000 ] && [ "$stalled" = true ] ||
    fail "--cells $c: ran to --max-shots ($shots shots, stalled '$stalled'): no stall rule"
  [ "$conv" = false ] || fail "--cells $c: converged '$conv'"
  # Checked every 10000 shots at a round's end; a round makes up to 16 shots a cell.
  [ "$shots" -ge 10000 ] && [ "$shots" -lt 14000 ] || fail "--cells $c: stalled after $shots shots"
  # The ledger: balanced, nothing absorbed, all of the emitted power still unshot.
  awk -v x="$err" -v u="$u" -v e="$e" -v a="$a" \
    'BEGIN { exit !(x <= 1e-6 && a == 0 && u / e > 1 - 1e-9 && u / e < 1 + 1e-9) }' ||
    fail "--cells $c: ledger: error $err, absorbed $a, unshot $u of $e"
  # The warnings (--quiet keeps them): before the solve, at the material's Kd line
  # (closed_white.mtl:2), with the first polygon that uses it (closed_box.obj:47: the
  # floor, id 0; nine walls, the light not counted), and the stall.
  grep -q "closed_white.mtl:2: warning: material 'white': reflectance 1 1 1 of polygon (id 0, [^)]*closed_box.obj:47) is 1 or more in a channel, so it absorbs nothing there (9 polygons in all, lights not counted): in a closed scene the solve may be slow or not reach --sf 0.001; .* Give --max-shots, or a reflectance below 1" \
    "$T/$tag.err" || fail "--cells $c: no reflectance warning: $(cat "$T/$tag.err")"
  grep -q "^vwalls radiosity: warning: stalled after $shots shots: the last [0-9]* absorbed or let escape [0-9.e+-]* of the emitted power, less than --sf 0.001, so the unshot power (100 % of the emitted) is only spread" \
    "$T/$tag.err" || fail "--cells $c: no stall warning: $(cat "$T/$tag.err")"
  [ "$(wc -l <"$T/$tag.err")" -eq 2 ] || fail "--cells $c: other messages: $(cat "$T/$tag.err")"
  [ -s "$T/$tag.csv" ] || fail "--cells $c: no CSV"
done

# --stall-shots N: checked every N shots; the summary says "stalled".
$TO "$V" radiosity "$T/closed_box.obj" $fast --stall-shots 2000 --stats "$T/s2k.json" \
  >"$T/s2k.out" 2>"$T/s2k.err" || fail "--stall-shots 2000: exit $?"
shots=$(field "$T/s2k.json" shots)
[ "$(field "$T/s2k.json" stalled)" = true ] && [ "$shots" -ge 2000 ] && [ "$shots" -le 2016 ] ||
  fail "--stall-shots 2000: $shots shots, $(cat "$T/s2k.json")"
grep -q "^radiosity: stalled, 27 pieces" "$T/s2k.out" || fail "--stall-shots: summary $(cat "$T/s2k.out")"
grep -q "when 2000 shots (--stall-shots) absorb" "$T/s2k.err" &&
  grep -q "or a larger --stall-shots than 2000$" "$T/s2k.err" || fail "--stall-shots: $(cat "$T/s2k.err")"
"$V" radiosity "$T/closed_box.obj" --stall-shots 0 --stats "$T/x.json" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] && grep -q "stall-shots" "$T/err" && [ ! -e "$T/x.json" ] || fail "--stall-shots 0: exit $rc $(cat "$T/err")"

# Red reflects everything, green and blue half: they are spent, red is not, and the
# solve stalls with a third of the emitted power unshot.
sed 's/^Kd 1 1 1$/Kd 1 0.5 0.5/' "$SRC/closed_white.mtl" >"$T/closed_white.mtl"
$TO "$V" radiosity "$T/closed_box.obj" $fast --stats "$T/red.json" --quiet 2>"$T/red.err" ||
  fail "red: exit $?"
u=$(field "$T/red.json" unshot) e=$(field "$T/red.json" emitted)
[ "$(field "$T/red.json" stalled)" = true ] &&
  awk -v u="$u" -v e="$e" 'BEGIN { exit !(u / e > 0.333 && u / e < 0.334) }' ||
  fail "red: $(cat "$T/red.json")"
grep -q "closed_white.mtl:2: warning: material 'white': reflectance 1 0.5 0.5 of polygon (id 0, [^)]*closed_box.obj:47) is 1 or more in a channel" "$T/red.err" ||
  fail "red: $(cat "$T/red.err")"

# Kd 0.9: converges, no warning, and --stall-shots (checked every 100 shots: each shot
# spends a tenth of its power) changes nothing of the solution.
sed 's/^Kd 1 1 1$/Kd 0.9 0.9 0.9/' "$SRC/closed_white.mtl" >"$T/closed_white.mtl"
for s in "" "--stall-shots 100"; do
  tag=grey${s:+100}
  $TO "$V" radiosity "$T/closed_box.obj" $fast $s --stats "$T/$tag.json" --csv "$T/$tag.csv" \
    --quiet 2>"$T/$tag.err" || fail "$tag: exit $?"
  [ "$(field "$T/$tag.json" converged)" = true ] && [ "$(field "$T/$tag.json" stalled)" = false ] ||
    fail "$tag: $(cat "$T/$tag.json")"
  [ ! -s "$T/$tag.err" ] || fail "$tag: a message: $(cat "$T/$tag.err")"
done
cmp -s "$T/grey.csv" "$T/grey100.csv" || fail "Kd 0.9: --stall-shots 100 changed the solution"

# A light of Kd 1 among grey walls: no warning.
printf 'newmtl white\nKd 0.5 0.5 0.5\nnewmtl light\nKd 1 1 1\nKe 10 10 10\n' >"$T/closed_white.mtl"
$TO "$V" radiosity "$T/closed_box.obj" $fast --stats "$T/l.json" --quiet 2>"$T/l.err" || fail "light: exit $?"
[ ! -s "$T/l.err" ] && [ "$(field "$T/l.json" converged)" = true ] || fail "light Kd 1: $(cat "$T/l.err")"

# Kd 1 with the floor taken out: the power escapes, the solve converges (with the
# warning: the mesher cannot tell a closed scene from an open one).
cp "$SRC/closed_white.mtl" "$T/"
sed '47d' "$SRC/closed_box.obj" >"$T/open.obj"
$TO "$V" radiosity "$T/open.obj" $fast --stats "$T/o.json" --quiet 2>"$T/o.err" || fail "open: exit $?"
[ "$(field "$T/o.json" converged)" = true ] && grep -q "closed_white.mtl:2: warning: material 'white': reflectance 1 1 1 of polygon (id 0, [^)]*open.obj:47)" "$T/o.err" ||
  fail "open box: $(cat "$T/o.err") $(cat "$T/o.json")"
echo "ok"
