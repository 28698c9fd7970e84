#!/bin/sh
# anim_counts.sh - what vwalls animate / edit count and say:
#  * the stats' animation.objects (and per_frame[].objects) count the live objects: a
#    removed object no longer counts (the top-level "objects" is the render world's
#    record slots, which a remove leaves in place, empty);
#  * per frame, "edits" are the edits applied (accepted, or rejected by the collision or
#    sweep test); lines refused as invalid are counted apart ("invalid", and ", N invalid
#    lines" on the frame line), not as edits;
#  * in --log, a line that does not parse names its command like one refused when
#    applied ("FILE:LINE: move: invalid: ..."); one whose first word is no command says
#    so in its message ("FILE:LINE: invalid: unknown command 'x'");
#  * 'balance' under --farm all (the default without --balance: every worker holds
#    every cell) says there is nothing to balance, not "lambda 1.000 -> 1.000" after a
#    frame line showing more; with --farm none it balances;
#  * animate's progress bar on a terminal, nothing of it off one.
# Usage: anim_counts.sh VWALLS WORKDIR
set -u
V=$1
W=$2
rm -rf "$W" && mkdir -p "$W" && cd "$W" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }

"$V" gen spheres --count 30 --seed 3 --resolution 16x16 -o scene.nff || fail "gen"

# Live objects: 30, then two removed and one added.
printf 'frame\nremove 1\nremove 2\nframe\nadd sphere 0 0 0 0.001\nframe\n' > rm.txt
"$V" animate scene.nff rm.txt -o 'r%d.png' --workers 2 --quiet --stats rm.json || fail "remove: status $?"
python3 - rm.json <<'PY' || fail "remove: the stats' objects"
import json, sys
a = json.load(open(sys.argv[1]))["animation"]
objs = [f["objects"] for f in a["per_frame"]]
assert objs == [30, 28, 29], objs
assert a["objects"] == 29, a
PY

# Edits against invalid lines: frame 1 has one accepted edit, one rejected by a
# collision (object 0 moved onto object 3) and three invalid lines: 2 edits, 3 invalid.
x=$(awk '$1 == "s" { n++; if (n == 4) { print $2, $3, $4; exit } }' scene.nff)
[ -n "$x" ] || fail "the scene's fourth sphere"
cat > ed.txt <<E
frame
remove 5
frobnicate 3
moveto 0 $x
move 1 nan 0 0
remove 999999
frame
E
"$V" animate scene.nff ed.txt -o 'e%d.png' --workers 2 --keep-going --stats ed.json --log ed.log \
  > out.txt 2> err.txt
rc=$?
[ $rc -eq 2 ] || fail "invalid lines: status $rc, expected 2: $(cat err.txt)"
python3 - ed.json <<'PY' || fail "invalid lines: the stats' edits: $(cat out.txt)"
import json, sys
a = json.load(open(sys.argv[1]))["animation"]
f = a["per_frame"][1]
assert (f["edits"], f["accepted"], f["invalid"]) == (2, 1, 3), f
assert (a["accepted"], a["collisions"], a["invalid"]) == (1, 1, 3), a
PY
grep -q '^frame 1: 2 edits (1 accepted), 3 invalid lines, ' out.txt ||
  fail "invalid lines: the frame line: $(grep '^frame 1' out.txt)"
grep -q '^frame 0: 0 edits (0 accepted), 0 records' out.txt ||
  fail "no invalid line: the frame line: $(grep '^frame 0' out.txt)"

# The log names the command of every invalid line that has one.
grep -qx 'ed.txt:3: invalid: unknown command .frobnicate.' ed.log || fail "log, unknown command: $(cat ed.log)"
grep -q '^ed.txt:5: move: invalid: bad number' ed.log || fail "log, a line that does not parse: $(cat ed.log)"
grep -q '^ed.txt:6: remove: invalid: ' ed.log || fail "log, a line refused when applied: $(cat ed.log)"
grep -q '^ed.txt:2: remove 5: accepted$' ed.log || fail "log, accepted: $(cat ed.log)"
grep -q '^ed.txt:4: moveto 0: rejected: collides' ed.log || fail "log, rejected: $(cat ed.log)"
# vwalls edit too (stdin), a wrong word count and a NUL byte.
printf 'frame 2\nmove 0 0 0 0.1\0x\nremove\n' |
  "$V" edit scene.nff --quiet --log sl.log > /dev/null 2>&1
grep -q '^stdin:1: frame: invalid: ' sl.log && grep -q '^stdin:2: move: invalid: a NUL byte' sl.log &&
  grep -q '^stdin:3: remove: invalid: ' sl.log || fail "edit's log: $(cat sl.log)"

# balance under --farm all (the default here) and --farm none.
printf 'frame\nbalance\n' > bal.txt
"$V" animate scene.nff bal.txt -o 'b%d.png' --cells 2x2x1 --workers 2 > bout.txt 2>&1 ||
  fail "balance, --farm all: status $?: $(cat bout.txt)"
grep -qx 'balance: nothing to balance with --farm all (every worker holds every cell): walls unchanged' bout.txt ||
  fail "balance, --farm all: $(cat bout.txt)"
grep -q 'lambda .* -> ' bout.txt && fail "balance, --farm all: a prediction: $(cat bout.txt)"
"$V" animate scene.nff bal.txt -o 'n%d.png' --cells 2x2x1 --workers 2 --farm none > nout.txt 2>&1 ||
  fail "balance, --farm none: status $?: $(cat nout.txt)"
grep -q '^balanced: lambda [0-9.]* -> [0-9.]* predicted$' nout.txt ||
  grep -q '^vwalls animate: .*no load balancer' nout.txt || fail "balance, --farm none: $(cat nout.txt)"
# --balance with an explicit --farm all: no rebalance between frames, said once.
printf 'frame\nframe\nframe\n' > three.txt
"$V" animate scene.nff three.txt -o 't%d.png' --cells 2x2x1 --workers 2 --farm all --balance tensor \
  --threshold 0 > tout.txt 2>&1 || fail "--balance --farm all: status $?: $(cat tout.txt)"
grep -q 'rebalanced' tout.txt && fail "--balance --farm all: rebalanced: $(cat tout.txt)"
[ "$(grep -c 'nothing to balance with --farm all' tout.txt)" -eq 1 ] ||
  fail "--balance --farm all: the note: $(cat tout.txt)"
# The progress bar: on a terminal (script(1) gives one) over the script's frames; off a
# terminal, nothing on stderr; none with --quiet.
printf 'frame\nmove 1 0 0 0.01\nframe\nframe\n' > pr.txt
"$V" animate scene.nff pr.txt -o 'pr%d.png' > pr.out 2> pr.err || fail "progress, off a terminal: status $?"
[ -s pr.err ] && fail "progress, off a terminal: stderr: $(cat -v pr.err)"
[ "$(grep -c '^frame ' pr.out)" -eq 3 ] || fail "progress, off a terminal: stdout: $(cat pr.out)"
if command -v script > /dev/null 2>&1 && script -qec true /dev/null > /dev/null 2>&1; then
  script -qec "'$V' animate scene.nff pr.txt -o 'pt%d.png'" /dev/null > pt.out 2>&1 ||
    fail "progress, on a terminal: status $?: $(cat -v pt.out)"
  grep -q 'animate \[#*\] 100.0% .* frame 3/3' pt.out || fail "progress, on a terminal: no bar: $(cat -v pt.out)"
  [ "$(grep -c 'frame [0-9]: ' pt.out)" -eq 3 ] || fail "progress, on a terminal: frame lines: $(cat -v pt.out)"
  script -qec "'$V' animate scene.nff pr.txt -o 'pq%d.png' --quiet" /dev/null > pq.out 2>&1 ||
    fail "progress, --quiet: status $?"
  [ -s pq.out ] && fail "progress, --quiet: $(cat -v pq.out)"
else
  echo "anim_counts: no script(1) giving a terminal: the bar on a terminal is not tested"
fi
echo "anim_counts ok"
