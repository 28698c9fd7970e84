#!/bin/sh
# cli.sh - vwalls animate / edit on the command line: frames and summary, stats JSON,
# bad lines (file:line on stderr, status 2, or skipped with --keep-going), the bad
# scripts of EDITS_DIR, edit on stdin.
# Usage: cli.sh VWALLS WORKDIR EDITS_DIR
set -u
V=$1
W=$2
E=$3
rm -rf "$W" && mkdir -p "$W" && cd "$W" || exit 1
fail() { echo "FAIL: $*" >&2; exit 1; }

"$V" gen spheres --count 200 --seed 3 --resolution 32x32 -o scene.nff || fail "gen"
cat > ok.txt <<'E'
# two frames
frame
check on
sweep on
move 0 0.1 0 0
add sphere 0 0 0 0.01
frame
E
"$V" animate scene.nff ok.txt -o 'f%02d.png' --cells 2x2x1 --workers 2 --stats s.json --log log.txt > out.txt \
  || fail "animate status $?"
[ -s f00.png ] && [ -s f01.png ] || fail "frames missing"
grep -q '"animation"' s.json || fail "no animation member in the stats"
grep -q '"command": "animate"' s.json || fail "stats command"
grep -q "accepted" out.txt || fail "no summary"
[ "$(wc -l < log.txt)" -eq 2 ] || fail "log should list both edits"
# Memory a batch of edits cannot get (the test switch VW_FAULT: a batch's bookkeeping,
# the room for its accepted edits): status 1 and the reason, not an edit taken as invalid
# (which, under MPI, would leave one process with another scene).
for f in batch commit; do
  [ $f = batch ] && what="preparing a batch of edits" || what="deciding a batch of edits"
  VW_FAULT=dynscene-$f-nomem "$V" animate scene.nff ok.txt -o 'm%02d.png' --cells 2x2x1 --workers 2 \
    --quiet 2>err.txt; rc=$?
  [ $rc -eq 1 ] || fail "dynscene-$f-nomem: status $rc"
  grep -q "^vwalls animate: applying edits: $what: out of memory\$" err.txt ||
    fail "dynscene-$f-nomem: message: $(cat err.txt)"
done
# No room for the contacts of the collider's query (VW_FAULT=collider-contacts-nomem):
# the query fails, and the message says where (cell C), not only that a batch failed.
# shellcheck disable=SC2046
set -- $(grep -m1 '^s ' scene.nff)
printf 'check on\nadd sphere %s %s %s 0.05\nframe\n' "$2" "$3" "$4" > hit.txt
VW_FAULT=collider-contacts-nomem "$V" animate scene.nff hit.txt -o 'm%02d.png' --cells 2x2x1 --workers 2 \
  --quiet 2>err.txt; rc=$?
[ $rc -eq 1 ] || fail "collider-contacts-nomem: status $rc"
grep -q "^vwalls animate: applying edits: checking a batch of edits for collisions: cell [0-9]*: out of memory for 64 contacts\$" err.txt ||
  fail "collider-contacts-nomem: message: $(cat err.txt)"
"$V" animate scene.nff hit.txt -o 'm%02d.png' --cells 2x2x1 --workers 2 --quiet --log hit.log ||
  fail "hit.txt without the fault: status $?"
grep -q "rejected: collides at its destination" hit.log || fail "hit.txt collides with nothing: $(cat hit.log)"
# --farm: auto is all (every worker holds every cell), idle with --balance; every mode
# gives the same frames.
grep -q '"farm": "all"' s.json || fail "default farm is not all: $(grep -o '"farm": "[a-z]*"' s.json)"
grep -q "(farm all)" out.txt || fail "the summary does not name the farm mode"
# Every frame has its counted-work lambda (ray segments per worker): at least 1.
python3 - s.json <<'PY' || fail "work_lambda per frame"
import json, sys
fr = json.load(open(sys.argv[1]))["animation"]["per_frame"]
assert len(fr) == 2 and all(f["work_lambda"] >= 1.0 for f in fr), fr
PY
for f in idle none; do
  "$V" animate scene.nff ok.txt -o "$f%02d.png" --cells 2x2x1 --workers 2 --farm $f --quiet \
    --stats $f.json || fail "--farm $f status $?"
  grep -q "\"farm\": \"$f\"" $f.json || fail "--farm $f not in the stats"
  cmp -s f00.png ${f}00.png && cmp -s f01.png ${f}01.png || fail "frames differ with --farm $f"
done
"$V" animate scene.nff ok.txt -o 't%02d.png' --cells 2x2x1 --workers 2 --balance tensor --quiet \
  --stats t.json || fail "--balance tensor status $?"
grep -q '"farm": "idle"' t.json || fail "--balance should farm idle workers only"
# --trigger work: the counted work decides the rebalances, so two runs agree on them.
for r in 1 2; do
  "$V" animate scene.nff ok.txt -o "w$r-%02d.png" --cells 2x2x1 --workers 2 --balance tensor \
    --threshold 0.2 --trigger work --quiet --stats w$r.json || fail "--trigger work status $?"
done
python3 - w1.json w2.json <<'PY' || fail "--trigger work: runs differ"
import json, sys
a, b = ([(f["work_lambda"], f["balanced"]) for f in json.load(open(x))["animation"]["per_frame"]]
        for x in sys.argv[1:])
assert a == b and all(bal == (lam > 1.2) for lam, bal in a), (a, b)
PY
# Without --trigger: busy time decides where the workers have cores of their own, the
# counted work where they outnumber them (busy time is then mostly waiting for a core).
VW_CORES=2 "$V" animate scene.nff ok.txt -o 'k%02d.png' --cells 2x2x1 --workers 4 --balance tensor \
  --stats crowded.json > crowded.out 2> crowded.err || fail "crowded: status $?"
grep -q '"trigger": "work"' crowded.json || fail "4 workers on 2 cores: trigger $(grep -o '"trigger": "[a-z]*"' crowded.json)"
grep -q "^vwalls animate: 4 workers on 2 cores: rebalancing when the counted work's lambda exceeds 1 + 0.1 (--trigger work)" crowded.err ||
  fail "4 workers on 2 cores: no note: $(cat crowded.err)"
head -1 crowded.out | grep -q "^frame 0:" || fail "the note went to standard output: $(head -1 crowded.out)"
VW_CORES=4 "$V" animate scene.nff ok.txt -o 'k%02d.png' --cells 2x2x1 --workers 4 --balance tensor \
  --quiet --stats roomy.json || fail "roomy: status $?"
grep -q '"trigger": "busy"' roomy.json || fail "4 workers on 4 cores: trigger $(grep -o '"trigger": "[a-z]*"' roomy.json)"
VW_CORES=2 "$V" animate scene.nff ok.txt -o 'k%02d.png' --cells 2x2x1 --workers 4 --balance tensor \
  --trigger busy --quiet --stats asked.json || fail "asked: status $?"
grep -q '"trigger": "busy"' asked.json || fail "--trigger busy: trigger $(grep -o '"trigger": "[a-z]*"' asked.json)"
# The balance command on walls no frame has measured yet (at the start, and right after
# a rebalance reset the loads) says so and leaves the walls; it used to report
# "lambda 1.000 -> 1.000". After a frame on unchanged walls it balances by that frame.
"$V" gen spheres --count 300 --cluster 1 --seed 3 --resolution 32x32 -o clustered.nff || fail "gen clustered"
printf 'balance\nframe\nbalance\n' > bal.txt
"$V" animate clustered.nff bal.txt -o 'b%02d.png' --cells 2x2x1 --workers 2 --balance tensor \
  --threshold 0 --trigger work > bal.out || fail "balance command: status $?"
sed -n 3p bal.out | grep -q "rebalanced (tensor)" || fail "balance command: frame 0 did not rebalance: $(cat bal.out)"
[ "$(grep -c "^balance: no load measured on the current walls yet (render a frame first): walls unchanged$" bal.out)" -eq 2 ] &&
  ! grep -q "1.000 -> 1.000" bal.out || fail "balance command without a measured load: $(cat bal.out)"
printf 'frame\nbalance\n' > bal2.txt
"$V" animate clustered.nff bal2.txt -o 'b%02d.png' --cells 2x2x1 --workers 2 --farm none > bal2.out ||
  fail "balance after a frame: status $?"
grep -Eq "^balanced: lambda 1\.[0-9]*[1-9][0-9]* -> 1\.[0-9]+ predicted$" bal2.out && ! grep -q "no load measured" bal2.out ||
  fail "balance after a frame: $(cat bal2.out)"
"$V" animate scene.nff ok.txt -o 'y%02d.png' --trigger most 2> yerr.txt; rc=$?
[ $rc -eq 2 ] || fail "--trigger most: status $rc, expected 2"
grep -q "trigger: bad value 'most'" yerr.txt || fail "--trigger most message: $(cat yerr.txt)"
"$V" animate scene.nff ok.txt -o 'x%02d.png' --farm most 2> xerr.txt; rc=$?
[ $rc -eq 2 ] || fail "--farm most: status $rc, expected 2"
grep -q "farm: bad value 'most'" xerr.txt || fail "--farm most message: $(cat xerr.txt)"
[ -e x00.png ] && fail "a frame was rendered with a bad --farm"
# Input the ray tracer refuses (a size beyond 16384, an eye beyond 1e36) is bad
# input as in render: status 2 (it was 1), the message, no frame.
"$V" animate scene.nff ok.txt -o 'z%02d.png' --size 20000x10 2> zerr.txt; rc=$?
[ $rc -eq 2 ] || fail "--size 20000x10: status $rc, expected 2"
grep -q "size: bad value '20000x10' (expected WIDTHxHEIGHT, like 512x512: sides of 1 to 16384)" zerr.txt ||
  fail "--size 20000x10 message: $(cat zerr.txt)"
sed 's/^from .*/from 3e37 3e37 3e37/' scene.nff > far.nff
echo frame | "$V" edit far.nff -o 'z%02d.png' 2> zerr.txt > /dev/null; rc=$?
[ $rc -eq 2 ] || fail "edit with an eye at 3e37: status $rc, expected 2"
grep -q "the eye lies 3e+37" zerr.txt || fail "eye at 3e37 message: $(cat zerr.txt)"
[ -e z00.png ] && fail "a frame was rendered from input the ray tracer refuses"
# Cells rebuilt per frame: every cell on the first frame and with --full-rebuild, else
# each cell the frame's edits touched, once however many batches touched it (vwalls edit
# makes a batch of every line: five moves of one sphere used to count its cells five
# times, more cells than the layout has).
printf 'frame\nmove 0 0.001 0 0\nmove 0 0.001 0 0\nmove 0 0.001 0 0\nmove 0 0.001 0 0\nmove 0 0.001 0 0\nframe\n' |
  "$V" edit scene.nff --cells 2x2x1 --workers 2 --quiet --stats rb.json > /dev/null || fail "edit (cells rebuilt): status $?"
"$V" animate scene.nff ok.txt -o 'fr%02d.png' --cells 2x2x1 --workers 2 --full-rebuild --quiet \
  --stats fr.json || fail "--full-rebuild: status $?"
python3 - rb.json fr.json <<'PY' || fail "cells_rebuilt per frame"
import json, sys
rb, fr = ([f["cells_rebuilt"] for f in json.load(open(x))["animation"]["per_frame"]] for x in sys.argv[1:])
assert rb[0] == 4 and 1 <= rb[1] <= 4, rb
assert fr == [4, 4], fr
PY
# One cell on two workers: the idle worker farms it (a copy, rebuilt with the cell
# after the edits); the frames are the same bytes.
"$V" animate scene.nff ok.txt -o 'g%02d.png' --cells 1 --workers 2 > gout.txt \
  || fail "animate --cells 1 status $?"
cmp -s f00.png g00.png && cmp -s f01.png g01.png || fail "frames differ with one cell farmed"

printf 'frame\nmove 999999 1 0 0\nfrobnicate 3\nmove 1 nan 0 0\nmoveto 2 1e9 0 0\nframe\n' > bad.txt
# Lines that do not parse are found before the first edit: all of them reported, and no
# frame, not even the one before them.
"$V" animate scene.nff bad.txt -o 'bad%02d.png' --workers 2 --log blog.txt > bout.txt 2> berr.txt
rc=$?
[ $rc -eq 2 ] || fail "bad script: status $rc, expected 2"
grep -q '^bad.txt:3: unknown command' berr.txt && grep -q '^bad.txt:4: bad number' berr.txt ||
  fail "unparsable lines not all reported: $(cat berr.txt)"
grep -q 'no object 999999' berr.txt && fail "an edit was applied before the script was checked"
[ -e bad00.png ] && fail "a frame was rendered from a script with a line that does not parse"
grep -q '2 invalid; 0 frames' bout.txt || fail "bad script summary: $(tail -1 bout.txt)"
[ "$(grep -c invalid blog.txt)" -eq 2 ] || fail "bad script log: $(cat blog.txt)"
# A line that parses but cannot be applied stops the run when it is reached: the frames
# before it stay, none after.
printf 'frame\nmove 999999 1 0 0\nframe\n' > badid.txt
"$V" animate scene.nff badid.txt -o 'i%02d.png' --workers 2 > /dev/null 2> ierr.txt
rc=$?
[ $rc -eq 2 ] || fail "unknown id script: status $rc, expected 2"
grep -q '^badid.txt:2: no object 999999' ierr.txt || fail "unknown id message: $(cat ierr.txt)"
[ -s i00.png ] || fail "the frame before the unknown id is missing"
[ -e i01.png ] && fail "a frame after the bad line was rendered"

# --keep-going renders every frame, and the bad lines still make the status 2; all four
# count as invalid and are in the log, the unparsable ones too.
"$V" animate scene.nff bad.txt -o 'k%02d.png' --workers 2 --keep-going --log klog.txt > kout.txt 2> kerr.txt
rc=$?
[ $rc -eq 2 ] || fail "--keep-going: status $rc, expected 2"
grep -q '^bad.txt:3: unknown command' kerr.txt || fail "unknown command message"
grep -q '^bad.txt:4: bad number' kerr.txt || fail "NaN message"
grep -q '^bad.txt:5: object 2 would leave the world' kerr.txt || fail "outside-world message: $(cat kerr.txt)"
[ -s k01.png ] || fail "--keep-going: second frame missing"
grep -q '4 invalid' kout.txt || fail "--keep-going: summary should count 4 invalid: $(tail -1 kout.txt)"
[ "$(grep -c invalid klog.txt)" -eq 4 ] || fail "--keep-going: the log should list 4 invalid lines: $(cat klog.txt)"
grep -q '^bad.txt:3: invalid: unknown command' klog.txt || fail "log of an unparsable line: $(cat klog.txt)"

# -o is a printf format: one integer conversion and a .png name, or status 2 and no file
# ('%s' and '%n' used to crash, '%x' to print the stack, no conversion to overwrite).
for pat in 'p%s.png' 'p%n.png' 'p%x.png' 'p%d%d.png' 'p.png' '' 'p%d' 'p%5000d.png' 'p%'; do
  rm -f p*
  "$V" animate scene.nff ok.txt -o "$pat" --size 8x8 --quiet 2> perr.txt; rc=$?
  [ $rc -eq 2 ] || fail "-o '$pat': status $rc, expected 2"
  grep -q -- "-o: bad pattern" perr.txt || fail "-o '$pat': message: $(cat perr.txt)"
  ls p* 2> /dev/null | grep -v perr.txt | grep -q . && fail "-o '$pat': a file was written"
done
"$V" animate scene.nff ok.txt -o 'q%%%03i.png' --size 8x8 --quiet || fail "-o 'q%%%03i.png': status $?"
[ -s 'q%000.png' ] && [ -s 'q%001.png' ] || fail "-o 'q%%%03i.png': frames missing"

# Lines of any length: a long comment is a comment (its tail used to run as a line of its
# own), a long command is one bad line; a NUL byte makes a bad line; a directory is not
# a script.
long=$(printf 'x%.0s' $(seq 1100))
printf 'frame\n# %s move 0 0 0 1\nframe\n' "$long" > long.txt
"$V" animate scene.nff long.txt -o 'l%02d.png' --size 8x8 --log llog.txt --quiet || fail "long comment: status $?"
grep -q move llog.txt && fail "the tail of a long comment was run: $(cat llog.txt)"
cmp -s l00.png l01.png || fail "long comment: the frames differ"
printf 'move 0 0 0 0.1 %s\nframe\n' "$long" > longc.txt
"$V" animate scene.nff longc.txt -o 'm%02d.png' --size 8x8 --quiet 2> lerr.txt; rc=$?
[ $rc -eq 2 ] && [ "$(wc -l < lerr.txt)" -eq 1 ] && grep -q '^longc.txt:1: line too long' lerr.txt \
  || fail "long command: status $rc, messages: $(cat lerr.txt)"
printf 'move 0 0 0 0.1\0garbage\nframe\n' > nul.txt
"$V" animate scene.nff nul.txt -o 'n%02d.png' --size 8x8 --quiet 2> nerr.txt; rc=$?
[ $rc -eq 2 ] && grep -q '^nul.txt:1: a NUL byte' nerr.txt || fail "NUL byte: status $rc: $(cat nerr.txt)"
mkdir -p adir
"$V" animate scene.nff adir -o 'd%02d.png' --size 8x8 --quiet 2> derr.txt; rc=$?
[ $rc -eq 2 ] && grep -q "cannot open 'adir': Is a directory" derr.txt || fail "directory script: status $rc: $(cat derr.txt)"

# A rotation about an axis too long to square (1e200) is the rotation about the unit
# axis (it used to scale the triangle, object 1, by cos 30 degrees).
printf 'v\nfrom 0 -6 2\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\nresolution 32 32\nl 3 -5 5\n%s\n' \
  'f 0.8 0.5 0.3 0.7 0.3 10 0 1 s 0 0 -1 0.5 p 3 -1 0 0 1 0 0 0 0 1.5' > tri.nff
for ax in '1e200 0 0' '1 0 0'; do
  printf 'rotate 1 %s 30\nframe\n' "$ax" > rot.txt
  "$V" animate tri.nff rot.txt -o "r${ax%% *}-%d.png" --quiet || fail "rotate $ax: status $?"
done
cmp -s r1e200-0.png r1-0.png || fail "rotate about 1e200,0,0 differs from rotate about 1,0,0"

# Every bad script of the corpus (its last line is the bad one): status 2, "file:line:
# why" naming that line, and no frame (a 'frame' is added after it). The good one runs.
n=0
for f in "$E"/bad_*.edits; do
  b=$(basename "$f")
  l=$(wc -l < "$f")
  { cat "$f"; echo frame; } > "$b"
  "$V" animate scene.nff "$b" -o 'c%02d.png' --workers 2 --quiet > /dev/null 2> cerr.txt; rc=$?
  [ $rc -eq 2 ] || fail "$b: status $rc, expected 2"
  grep -Eq "^$b:$l: [a-z]" cerr.txt || fail "$b: no '$b:$l: why' message: $(cat cerr.txt)"
  [ -e c00.png ] && fail "$b: a frame was rendered"
  n=$((n + 1))
done
[ $n -ge 10 ] || fail "only $n bad scripts in $E"
"$V" animate scene.nff "$E/good_moves.edits" -o 'ok%02d.png' --cells 2x2x1 --workers 2 --quiet \
  || fail "good_moves.edits: status $?"
[ -s ok00.png ] && [ -s ok01.png ] || fail "good_moves.edits: frames missing"

printf 'move 0 0.05 0 0\nbogus\nremove 1\nremove 1\nframe\n' | "$V" edit scene.nff -o 'e%02d.png' --workers 1 > eout.txt 2> eerr.txt
rc=$?
[ $rc -eq 2 ] || fail "edit: status $rc, expected 2 (it went on past two bad lines)"
printf 'move 0 0.05 0 0\n' | "$V" edit scene.nff --workers 1 --quiet > qout.txt || fail "edit --quiet: status $?"
grep -q 'move 0: accepted' qout.txt || fail "edit --quiet: the answer is missing"
grep -q 'objects; commands' qout.txt && fail "edit --quiet: the banner was printed"
grep -q 'remove 1: accepted' eout.txt || fail "edit: no answer"
grep -q '^stdin:2: unknown command' eerr.txt || fail "edit: bad line message"
grep -q '^stdin:4: no object 1' eerr.txt || fail "edit: removed id message"
[ -s e00.png ] || fail "edit: frame missing"
# Line ends: LF, CRLF and a lone CR (classic Mac OS) run the same edits, and a bad
# line is named by the same number.
for ends in lf crlf cr; do
  case $ends in lf) e='\n' ;; crlf) e='\r\n' ;; cr) e='\r' ;; esac
  printf "move 0 0.05 0 0${e}bogus${e}remove 1${e}frame${e}" > "ends_$ends.txt"
  "$V" animate scene.nff "ends_$ends.txt" -o "ends_$ends%02d.png" --workers 1 --keep-going \
    > "ends_$ends.out" 2> "ends_$ends.err"
  rc=$?
  [ $rc -eq 2 ] || fail "$ends line ends: status $rc, expected 2"
  grep -q "^ends_$ends.txt:2: unknown command" "ends_$ends.err" ||
    fail "$ends line ends: line 2 not named: $(cat "ends_$ends.err")"
  grep -q '2 accepted' "ends_$ends.out" || fail "$ends line ends: $(tail -1 "ends_$ends.out")"
done
cmp -s ends_lf00.png ends_cr00.png && cmp -s ends_lf00.png ends_crlf00.png ||
  fail "the frames differ between LF, CRLF and CR line ends"
# --stats that cannot be written says why, before any frame (it used to fail after the
# last one); so does a frames directory that does not exist.
rm -f st*.png
"$V" animate scene.nff "$E/good_moves.edits" -o 'st%02d.png' --workers 1 --quiet \
  --stats nodir/s.json 2> sterr.txt; rc=$?
[ $rc -eq 1 ] || fail "--stats into a missing directory: status $rc"
grep -q -- '--stats nodir/s.json: cannot write: nodir: No such file' sterr.txt || fail "--stats: no reason: $(cat sterr.txt)"
! ls st*.png > /dev/null 2>&1 || fail "--stats into a missing directory: frames written"
"$V" animate scene.nff "$E/good_moves.edits" -o 'nodir/st%02d.png' --workers 1 --quiet 2> sterr.txt; rc=$?
[ $rc -eq 1 ] || fail "frames into a missing directory: status $rc"
grep -q -- '-o nodir/st%02d.png: cannot write: nodir: No such file' sterr.txt || fail "-o: no reason: $(cat sterr.txt)"
"$V" animate scene.nff 2> /dev/null; [ $? -eq 2 ] || fail "usage status"
echo "cli ok"
