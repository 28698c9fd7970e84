#!/bin/sh
# cli.sh VWALLS SRCDIR TMPDIR TEST_RADIOSITY - the command line of `vwalls radiosity`: bad input is
# "file:line: message" with exit 2 and no output file; a kill after a checkpoint
# resumes to the uninterrupted solution.
set -u
V=$1 SRC=$2 T=$3 TR=$4
rm -rf "$T" && mkdir -p "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

"$V" radiosity "$SRC/no_emitter.obj" -o "$T/a.ply" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "no emitter: exit $rc"
grep -q "no emitter" "$T/err" || fail "no emitter: message: $(cat "$T/err")"
[ ! -e "$T/a.ply" ] || fail "no emitter: output written"

cp "$SRC/nonplanar.obj" "$SRC/light.mtl" "$T/"
"$V" radiosity "$T/nonplanar.obj" -o "$T/b.ply" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "non-planar: exit $rc"
grep -q "nonplanar.obj:7: polygon (id 0) is not planar" "$T/err" || fail "non-planar: message: $(cat "$T/err")"
[ ! -e "$T/b.ply" ] || fail "non-planar: output written"

"$V" radiosity "$T/missing.obj" -o "$T/c.ply" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "missing file: exit $rc"
"$V" radiosity "$T/nonplanar.obj" -o "$T/c.ply" --hemicube 7 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "odd hemicube: exit $rc"

# Kill after a checkpoint, resume, compare with the uninterrupted run.
"$TR" gen cornell "$T/cornell.nff" || fail "gen"
opts="--cells 2x2x2 --workers 2 --sf 2e-4 --quiet"
"$V" radiosity "$T/cornell.nff" $opts --csv "$T/full.csv" 2>/dev/null || fail "uninterrupted run"
"$V" radiosity "$T/cornell.nff" $opts --csv "$T/never.csv" --checkpoint "$T/ck" --checkpoint-every 0 2>/dev/null &
pid=$!
i=0
while [ ! -s "$T/ck" ] && [ $i -lt 400 ]; do sleep 0.02; i=$((i+1)); done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
[ -s "$T/ck" ] || fail "no checkpoint written"
[ ! -e "$T/never.csv" ] || echo "note: the run ended before the kill"
ls "$T" | grep -q "tmp\." && fail "temporary file left behind"
"$V" radiosity "$T/cornell.nff" $opts --csv "$T/resumed.csv" --resume "$T/ck" 2>/dev/null || fail "resume"
"$TR" csvcmp "$T/full.csv" "$T/resumed.csv" 0.01 || fail "resumed differs"

# Without --cells: one cell for one worker, at least 4 a worker for more; fewer cells
# than workers given: a warning (radiosity cells cannot be shared).
layout() { sed -n 's/.*"layout": "\([0-9x]*\)".*/\1/p' "$1" | head -n 1; }
"$V" radiosity "$T/cornell.nff" -o "$T/d1.ply" --workers 1 --sf 1e-2 --quiet --stats "$T/d1.json" \
  --trace "$T/d1.trace" || fail "default cells, 1 worker"
# --trace: a line "seconds shots unshot_ratio" per round, the last ratio at or below sf.
awk 'NF != 3 || $2 < 0 { bad = 1 } END { exit bad || NR < 1 || $3 > 0.01 }' "$T/d1.trace" \
  || fail "--trace: $(head -n 3 "$T/d1.trace")"
[ "$(layout "$T/d1.json")" = 1x1x1 ] || fail "default cells for 1 worker: $(layout "$T/d1.json")"
"$V" radiosity "$T/cornell.nff" -o "$T/d2.ply" --workers 2 --sf 1e-2 --quiet --stats "$T/d2.json" || fail "default cells, 2 workers"
[ "$(layout "$T/d2.json")" = 2x2x2 ] || fail "default cells for 2 workers: $(layout "$T/d2.json")"
"$V" radiosity "$T/cornell.nff" -o "$T/d3.ply" --workers 2 --cells 1 --sf 1e-2 2>"$T/err" >/dev/null || fail "1 cell, 2 workers"
grep -q "warning: 1 cell for 2 workers: 1 of them will idle" "$T/err" || fail "no idle warning: $(cat "$T/err")"
echo "ok"
