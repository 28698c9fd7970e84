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

# Polygons that cross themselves: no one inside to mesh (a star was fanned over its
# centre twice).
cp "$SRC/star.obj" "$SRC/bowtie.obj" "$T/"
for case in "star.obj:11:corners 2 and 4" "bowtie.obj:10:corners 1 and 3"; do
  f=${case%%:*} rest=${case#*:}
  "$V" radiosity "$T/$f" -o "$T/s.ply" 2>"$T/err"; rc=$?
  [ $rc -eq 2 ] || fail "$f: exit $rc"
  grep -q "$f:${rest%%:*}: polygon (id 0) crosses itself (its edges from ${rest#*:})" "$T/err" \
    || fail "$f: message: $(cat "$T/err")"
  [ ! -e "$T/s.ply" ] || fail "$f: output written"
done

"$V" radiosity "$T/missing.obj" -o "$T/c.ply" 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "missing file: exit $rc"
"$V" radiosity "$T/nonplanar.obj" -o "$T/c.ply" --hemicube 7 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "odd hemicube: exit $rc"

"$TR" gen cornell "$T/cornell.nff" || fail "gen"

# --view that gives no view: exit 2, the reason, no picture (a NaN, a field of view
# out of range or 'from' equal to 'at' used to be taken as they came, or made 45).
for bad in "1,2,nan,0,0,0:finite numbers" "0,0,0,0,0,0:the same point" \
           "1,1,1,0,0,0,200:field of view 200 out of range" "1,1,1,0,0,0,30,5:finite numbers" \
           "1,1,1,0,0,0,0:field of view 0 out of range (above 0 and below 180 degrees)" \
           "1,1,1,0,0,0,180:field of view 180 out of range"; do
  val=${bad%%:*} want=${bad#*:}
  "$V" radiosity "$T/cornell.nff" --image "$T/v.png" --view "$val" --max-shots 4 --quiet \
    2>"$T/err"; rc=$?
  [ $rc -eq 2 ] || fail "--view $val: exit $rc"
  grep -q "$want" "$T/err" || fail "--view $val: message: $(cat "$T/err")"
  [ ! -e "$T/v.png" ] || fail "--view $val: picture written"
done
# The field of view of an NFF file's range, as render --angle takes it (179 was the most).
"$V" radiosity "$T/cornell.nff" --image "$T/v.png" --view 278,273,-800,278,273,0,179.5 --size 8x8 \
  --max-shots 4 --quiet 2>"$T/err" && [ -s "$T/v.png" ] || fail "--view FOV 179.5: $(cat "$T/err")"
rm -f "$T/v.png"
# The short and long spellings every other command takes: -q and --output (radiosity
# took only --quiet and -o), and gen's --output.
"$V" radiosity "$T/cornell.nff" --output "$T/q.ply" -q --max-shots 4 >"$T/out" 2>"$T/err" \
  && [ -s "$T/q.ply" ] && [ ! -s "$T/out" ] || fail "--output/-q: $(cat "$T/err" "$T/out")"
"$V" gen cornell --output "$T/g.nff" 2>"$T/err" && "$V" gen cornell >"$T/g2.nff" \
  && cmp -s "$T/g.nff" "$T/g2.nff" \
  || fail "gen --output: $(cat "$T/err")"
# A patch size far below the scene's: refused before meshing (it used to overflow the
# patch indices and report "no polygon to mesh").
"$V" radiosity "$T/cornell.nff" -o "$T/p.ply" --patch-size 1e-9 --quiet 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "--patch-size 1e-9: exit $rc"
grep -q "patch size 1e-09 is too small" "$T/err" || fail "--patch-size 1e-9: message: $(cat "$T/err")"
[ ! -e "$T/p.ply" ] || fail "--patch-size 1e-9: output written"
# A solve larger than the memory left: refused before it starts (it used to fail part-way,
# or be killed), with the estimate; the estimate follows --elements and --max-level
# (--elements 8: about 43,000 elements of 300 bytes, 13 MB; with --subdivide and
# --max-level 3, 64 fine cells of 60 bytes each more, about 180 MB).
VW_MEM_AVAILABLE=5000000 "$V" radiosity "$T/cornell.nff" -o "$T/m.ply" --elements 8 --quiet \
  2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "memory: exit $rc"
grep -q "the solve needs about 1[0-9] MB a process (4[0-9]* elements of about 300 bytes), more than the 5 MB" \
  "$T/err" || fail "memory: message: $(cat "$T/err")"
[ ! -e "$T/m.ply" ] || fail "memory: output written"
VW_MEM_AVAILABLE=50000000 "$V" radiosity "$T/cornell.nff" -o "$T/m.ply" --elements 8 --max-shots 4 \
  --quiet 2>"$T/err" && [ -s "$T/m.ply" ] || fail "memory: 50 MB: $(cat "$T/err")"
rm -f "$T/m.ply"
VW_MEM_AVAILABLE=50000000 "$V" radiosity "$T/cornell.nff" -o "$T/m.ply" --elements 8 --subdivide 0.1 \
  --max-level 3 --quiet 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "memory, --max-level 3: exit $rc"
grep -q "needs about 1[5-9][0-9] MB a process" "$T/err" || fail "memory, --max-level 3: $(cat "$T/err")"
[ ! -e "$T/m.ply" ] || fail "memory, --max-level 3: output written"
# sf above every patch's share of the emitted power: converged at once, and said so.
"$V" radiosity "$T/cornell.nff" -o "$T/p.ply" --sf 0.5 >/dev/null 2>"$T/err" || fail "--sf 0.5"
grep -q "warning: converged before the first shot" "$T/err" || fail "--sf 0.5: no warning"
"$V" radiosity "$T/cornell.nff" -o "$T/p.ply" --max-shots 4 >/dev/null 2>"$T/err" || fail "a run"
! grep -q "before the first shot" "$T/err" || fail "a run that shot: a warning: $(cat "$T/err")"
# The generated Cornell box is clean geometry: no meshing warning (the published red
# wall, 0.8 mm off planar, was flattened with one; gen now writes it as two triangles).
! grep -q "warning" "$T/err" || fail "Cornell box: a warning: $(cat "$T/err")"
# --quiet silences the progress bar and the summary, not the warnings (it used to drop
# all three: the meshing warning, the idle workers, nothing lit). A polygon a little
# off planar is flattened with one warning at its own line.
cp "$SRC/slightly_nonplanar.obj" "$T/"
"$V" radiosity "$T/slightly_nonplanar.obj" -o "$T/p.ply" --sf 0.5 --cells 2 --workers 4 --quiet \
  >"$T/out" 2>"$T/qerr" || fail "--quiet: $(cat "$T/qerr")"
[ ! -s "$T/out" ] || fail "--quiet printed a summary: $(cat "$T/out")"
for w in "slightly_nonplanar.obj:9: warning: polygon (id 0) is not planar (0.0025 off), flattened" \
         "warning: 2 cells for 4 workers" "warning: converged before the first shot"; do
  grep -q "$w" "$T/qerr" || fail "--quiet dropped '$w': $(cat "$T/qerr")"
done
[ "$(grep -c "warning: polygon" "$T/qerr")" = 1 ] || fail "non-planar warnings: $(cat "$T/qerr")"
# Kd 5 on the white of the floor and the ceiling (line 11; polygons 0-4): the solver
# clamps it to 1, the CSV says 1, and one warning names the material's 'f' line and the
# first polygon's; a second says that the clamped surfaces absorb nothing (the solve may
# stall).
sed '11s/.*/f 1 1 1 5 0 0 0 1/' "$T/cornell.nff" >"$T/kd5.nff"
"$V" radiosity "$T/kd5.nff" --csv "$T/kd5.csv" --sf 0.01 --patch-size 200 --max-shots 4 \
  >/dev/null 2>"$T/err" || fail "Kd 5: $(cat "$T/err")"
awk -F, '$1 == 0 && $3 == 1 && $4 == 1 && $5 == 1 { ok = 1 } END { exit !ok }' "$T/kd5.csv" \
  || fail "Kd 5: CSV reflectance: $(sed -n 2p "$T/kd5.csv")"
[ "$(grep -c "reflectance" "$T/err")" = 2 ] &&
  grep -q "kd5.nff:11: warning: reflectance 5 5 5 of polygon (id 0, [^)]*kd5.nff:12) is outside \[0, 1\], clamped (5 polygons in all)" \
    "$T/err" &&
  grep -q "kd5.nff:11: warning: reflectance 5 5 5 of polygon (id 0, [^)]*kd5.nff:12) is 1 or more in a channel, so it absorbs nothing there (5 polygons in all, lights not counted)" \
    "$T/err" || fail "Kd 5: warning: $(cat "$T/err")"
# --image: .pfm is a float map (header, then 16x16 RGB floats), any other name but .png
# is refused before the solve (.jpg used to get PNG bytes).
"$V" radiosity "$T/cornell.nff" --image "$T/v.pfm" --size 16x16 --max-shots 4 --quiet 2>"$T/err" \
  || fail "--image .pfm: $(cat "$T/err")"
[ "$(head -c 14 "$T/v.pfm" | tr '\n' ' ')" = "PF 16 16 -1.0 " ] && [ "$(wc -c <"$T/v.pfm")" -eq $((14 + 16 * 16 * 12)) ] \
  || fail "--image .pfm: not a 16x16 PFM: $(head -c 15 "$T/v.pfm" | od -c | head -n 2)"
"$V" radiosity "$T/cornell.nff" --image "$T/v.jpg" -o "$T/v.ply" --max-shots 4 --quiet 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "--image .jpg: exit $rc"
grep -q "image .*v.jpg: the picture must end in .png or .pfm" "$T/err" || fail "--image .jpg: message: $(cat "$T/err")"
[ ! -e "$T/v.jpg" ] && [ ! -e "$T/v.ply" ] || fail "--image .jpg: output written"
# -o is read back as a scene by its name: a mesh named .obj (PLY inside) is refused
# before the solve; a device takes any name.
"$V" radiosity "$T/cornell.nff" -o "$T/m.obj" --max-shots 4 --quiet 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "-o m.obj: exit $rc"
grep -q "radiosity: -o .*m.obj: written as PLY, which vwalls reads only from a name ending in .ply" "$T/err" ||
  fail "-o m.obj: message: $(cat "$T/err")"
[ ! -e "$T/m.obj" ] || fail "-o m.obj: output written"
"$V" radiosity "$T/cornell.nff" -o /dev/null --max-shots 4 --quiet || fail "-o /dev/null: exit $?"
# A scene file's own resolution beyond 16384 a side: refused before the solve, as render
# refuses it (it was allocated after the solve); --size overrides it.
sed 's/^resolution .*/resolution 20000 10/' "$T/cornell.nff" > "$T/wide.nff"
"$V" radiosity "$T/wide.nff" --image "$T/w.png" -o "$T/w.ply" --max-shots 4 --quiet 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "resolution 20000 10: exit $rc"
grep -q "picture size 20000x10 too large (at most 16384 on a side" "$T/err" ||
  fail "resolution 20000 10: message: $(cat "$T/err")"
[ ! -e "$T/w.png" ] && [ ! -e "$T/w.ply" ] || fail "resolution 20000 10: output written"
"$V" radiosity "$T/wide.nff" --image "$T/w.png" --size 16x8 --max-shots 4 --quiet 2>"$T/err" ||
  fail "resolution 20000 10 with --size 16x8: $(cat "$T/err")"
# A run whose energy ledger does not add up (forced by the test switch VW_FAULT=ledger)
# fails with status 1 and leaves none of its outputs: the check comes before the writes
# (they used to be written complete, and the run failed after them).
VW_FAULT=ledger "$V" radiosity "$T/cornell.nff" -o "$T/l.ply" --csv "$T/l.csv" --image "$T/l.png" \
  --stats "$T/l.json" --trace "$T/l.trace" --checkpoint "$T/l.ck" --size 16x16 --max-shots 4 \
  --quiet 2>"$T/err"; rc=$?
[ $rc -eq 1 ] || fail "ledger off: exit $rc"
grep -q "energy ledger off by inf (relative): no output written" "$T/err" || fail "ledger off: message: $(cat "$T/err")"
for f in l.ply l.csv l.png l.json l.trace l.ck; do [ ! -e "$T/$f" ] || fail "ledger off: $f written"; done
ls "$T" | grep -q "tmp\." && fail "ledger off: temporary file left behind"
# Memory that runs out during the solve (the test switch VW_FAULT: solve-nomem fails every
# allocation of the solve's handlers and steps, collect-nomem those of the collected
# solution): status 1, the reason, no output. It used to end the process with SIGABRT.
for f in solve collect; do
  [ $f = solve ] && want="cell [0-9]*: out of memory ([0-9]* bytes) in the solve" ||
    want="out of memory ([0-9]* bytes) collecting the solution"
  for sub in "" "--subdivide 0.5"; do
    VW_FAULT=$f-nomem "$V" radiosity "$T/cornell.nff" -o "$T/m.ply" --csv "$T/m.csv" --image "$T/m.png" \
      --stats "$T/m.json" --size 16x16 --max-shots 40 --cells 2x2x2 --workers 2 $sub --quiet 2>"$T/err"; rc=$?
    [ $rc -eq 1 ] || fail "$f-nomem $sub: exit $rc"
    grep -q "^vwalls radiosity: radiosity run failed: $want\$" "$T/err" || fail "$f-nomem $sub: message: $(cat "$T/err")"
    for x in m.ply m.csv m.png m.json; do [ ! -e "$T/$x" ] || fail "$f-nomem $sub: $x written"; done
  done
done
ls "$T" | grep -q "tmp\." && fail "no memory: temporary file left behind"
# Looking straight down (+y up would be parallel to the view): +z is up instead.
"$V" radiosity "$T/cornell.nff" --image "$T/v.png" --view 278,540,280,278,0,280,100 \
  --size 16x16 --max-shots 4 --quiet 2>"$T/err" || fail "vertical --view: $(cat "$T/err")"
[ -s "$T/v.png" ] || fail "vertical --view: no picture"

# Kill after a checkpoint, resume, compare with the uninterrupted run.
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

# A checkpoint continues only a run with the options its state depends on: each of
# these is refused (status 2, no output); --sf and --per-round may change.
small="--sf 0.01 --patch-size 200 --per-round 1 --cells 2x2x2 --quiet"
"$V" radiosity "$T/cornell.nff" $small --checkpoint "$T/k2" --checkpoint-every 0 --max-rounds 2 \
  || fail "small checkpoint"
for bad in "--elements 3:--elements 2 there, 3 here" "--hemicube 32:--hemicube 64 there, 32 here" \
           "--subdivide 0.3:--subdivide none there, 0.3 here" "--patch-size 150:--patch-size 200 there, 150 here" \
           "--neighbourhood 300:--neighbourhood none there, 300 here" "--cells 2x2x1:--cells 2x2x2 there, 2x2x1 here"; do
  opt=${bad%%:*} want=${bad#*:}
  "$V" radiosity "$T/cornell.nff" $small $opt --resume "$T/k2" --csv "$T/k2.csv" 2>"$T/err"; rc=$?
  [ $rc -eq 2 ] || fail "resume with $opt: exit $rc"
  grep -q "k2: checkpoint of a different scene or meshing ($want;" "$T/err" \
    || fail "resume with $opt: message: $(cat "$T/err")"
  [ ! -e "$T/k2.csv" ] || fail "resume with $opt: output written"
done
"$V" radiosity "$T/cornell.nff" $small --sf 0.005 --per-round 3 --resume "$T/k2" --csv "$T/k2.csv" \
  || fail "resume with another --sf and --per-round"

# A damaged checkpoint is refused (status 2, no output), naming what is wrong: it used
# to be resumed, and a NaN went through the solve into the CSV and the stats JSON.
# Offsets (solve.c, format 2): absorbed[0] at 36, the patches from 140 (40 bytes each,
# unshot[0] at +16), the last element's B[0] 80 - 32 + 8 bytes before the end.
poke() { printf "$3" | dd of="$1" bs=1 seek="$2" conv=notrunc 2>/dev/null; }
nan='\000\000\000\000\000\000\370\177' one='\000\000\000\000\000\000\360\077'
size=$(wc -c <"$T/k2")
for bad in "36:$nan:absorbed power r nan" "356:$nan:patch 5: unshot power r nan" \
           "$((size * 9 / 10)):\377\377\377\377\377\377\377\377:" \
           "$((size - 56)):$one:checksum mismatch" "truncate::bytes for"; do
  off=${bad%%:*} rest=${bad#*:}; bytes=${rest%%:*} want=${rest#*:}
  if [ "$off" = truncate ]; then head -c $((size - 1)) "$T/k2" >"$T/kbad"
  else cp "$T/k2" "$T/kbad" && poke "$T/kbad" "$off" "$bytes"; fi
  rm -f "$T/kbad.csv" "$T/kbad.json"
  "$V" radiosity "$T/cornell.nff" $small --resume "$T/kbad" --csv "$T/kbad.csv" --stats "$T/kbad.json" \
    2>"$T/err"; rc=$?
  [ $rc -eq 2 ] || fail "checkpoint damaged at $off: exit $rc"
  grep -q "kbad: truncated or corrupt checkpoint (.*$want" "$T/err" \
    || fail "checkpoint damaged at $off: message: $(cat "$T/err")"
  [ ! -e "$T/kbad.csv" ] && [ ! -e "$T/kbad.json" ] || fail "checkpoint damaged at $off: output written"
done

# Without --cells: one cell for one worker, at least 4 a worker for more; fewer cells
# than workers given: a warning (radiosity cells cannot be shared).
layout() { sed -n 's/.*"layout": "\([0-9x]*\)".*/\1/p' "$1" | head -n 1; }
"$V" radiosity "$T/cornell.nff" -o "$T/d1.ply" --workers 1 --sf 1e-2 --quiet --stats "$T/d1.json" \
  --trace "$T/d1.trace" || fail "default cells, 1 worker"
# --trace: a line "seconds shots unshot_ratio" per round, the last ratio at or below sf.
awk 'NF != 3 || $2 < 0 { bad = 1 } END { exit bad || NR < 1 || $3 > 0.01 }' "$T/d1.trace" \
  || fail "--trace: $(head -n 3 "$T/d1.trace")"
# An output that cannot be written is found before any work (it used to be found after
# the whole solve, with the outputs before it written): status 1, nothing written, and
# before the scene is even read.
"$V" radiosity "$T/cornell.nff" -o "$T/w.ply" --csv "$T/nodir/w.csv" --max-shots 4 --quiet 2>"$T/err"; rc=$?
[ $rc -eq 1 ] || fail "--csv in a missing directory: exit $rc"
grep -q -- "--csv .*nodir/w.csv: cannot write: .*nodir: No such file or directory" "$T/err" \
  || fail "--csv in a missing directory: message: $(cat "$T/err")"
[ ! -e "$T/w.ply" ] || fail "--csv in a missing directory: the PLY was written"
# The last output cannot be written (the stats to a full disk): the mesh, the CSV and
# the trace, complete by then, are not put in place either (vw_outfile_hold).
if [ -e /dev/full ]; then
  rm -f "$T/f.ply" "$T/f.csv" "$T/f.trace"
  "$V" radiosity "$T/cornell.nff" -o "$T/f.ply" --csv "$T/f.csv" --trace "$T/f.trace" --stats /dev/full \
    --max-shots 4 --quiet 2>"$T/err"; rc=$?
  [ $rc -eq 1 ] && grep -q "/dev/full: write failed: No space left on device" "$T/err" \
    || fail "--stats /dev/full: exit $rc, $(cat "$T/err")"
  for f in f.ply f.csv f.trace; do [ ! -e "$T/$f" ] || fail "--stats /dev/full: $f written"; done
  ls "$T" | grep -q '\.tmp\.' && fail "--stats /dev/full: temporary files left: $(ls "$T")"
fi
"$V" radiosity "$T/missing.obj" --stats "$T" 2>"$T/err"; rc=$?
[ $rc -eq 1 ] && grep -q -- "--stats .*: cannot write: it is a directory" "$T/err" \
  || fail "--stats DIR: exit $rc, $(cat "$T/err")"
# No output asked for: the message names every output option; --trace alone, like
# --checkpoint alone, is an output (it used to be refused as "no output").
"$V" radiosity "$T/cornell.nff" --max-shots 4 2>"$T/err"; rc=$?
[ $rc -eq 2 ] || fail "no output: exit $rc"
grep -q "no output: give -o OUT.ply, --csv F, --image F, --stats F, --trace F or --checkpoint F" "$T/err" \
  || fail "no output: message: $(cat "$T/err")"
"$V" radiosity "$T/cornell.nff" --trace "$T/only.trace" --max-shots 4 --quiet 2>"$T/err" \
  || fail "--trace alone: $(cat "$T/err")"
[ -s "$T/only.trace" ] || fail "--trace alone: no trace"
# Each --trace line is one moment: stopped by --max-shots, the last line is the state
# the stats report (it used to pair the shots after a round with the ratio before it:
# "12 0.0674" against 12 shots and 0.0177), and the first is the start (0 shots).
"$V" radiosity "$T/cornell.nff" -o "$T/ms.ply" --sf 0.001 --patch-size 200 --per-round 1 --max-shots 5 \
  --stats "$T/ms.json" --trace "$T/ms.trace" --quiet || fail "--trace with --max-shots"
final=$(sed -n 's/.*"radiosity": {"shots": \([0-9]*\), "unshot_ratio": \([^,]*\),.*/\1 \2/p' "$T/ms.json")
awk -v f="$final" 'BEGIN { split(f, s, " ") } NR == 1 && $2 != 0 { bad = 1 } { n = $2; u = $3 }
  END { exit bad || n != s[1] || (u - s[2]) ^ 2 > (1e-6 * s[2]) ^ 2 }' "$T/ms.trace" \
  || fail "--trace: last line $(tail -n 1 "$T/ms.trace"), stats: $final"
[ "$(layout "$T/d1.json")" = 1x1x1 ] || fail "default cells for 1 worker: $(layout "$T/d1.json")"
"$V" radiosity "$T/cornell.nff" -o "$T/d2.ply" --workers 2 --sf 1e-2 --quiet --stats "$T/d2.json" || fail "default cells, 2 workers"
[ "$(layout "$T/d2.json")" = 2x2x2 ] || fail "default cells for 2 workers: $(layout "$T/d2.json")"
"$V" radiosity "$T/cornell.nff" -o "$T/d3.ply" --workers 2 --cells 1 --sf 1e-2 2>"$T/err" >/dev/null || fail "1 cell, 2 workers"
grep -q "warning: 1 cell for 2 workers: 1 of them will idle" "$T/err" || fail "no idle warning: $(cat "$T/err")"
# Out of memory while the cells are built (most of a cell's memory is taken there):
# exit 1 naming the cell, no output. It used to abort (SIGABRT, status 134). The
# address-space limit stands in for a small machine (one worker: one cell, built
# alone, so where it fails does not depend on timing); a sanitizer build cannot start
# under it, so the case is skipped there.
if (ulimit -v 250000 && "$V" --version) >/dev/null 2>&1; then
  (ulimit -v 250000 && exec "$V" radiosity "$T/cornell.nff" -o "$T/nomem.ply" --elements 48 --workers 1 \
    --quiet) 2>"$T/err"; rc=$?
  [ $rc -eq 1 ] || fail "out of memory: exit $rc: $(cat "$T/err")"
  grep -q "building cell [0-9]* failed: out of memory" "$T/err" || fail "out of memory: message: $(cat "$T/err")"
  [ ! -e "$T/nomem.ply" ] || fail "out of memory: output written"
else
  echo "SKIP: out of memory (the program cannot start under a 250 MB address-space limit)"
fi
echo "ok"
