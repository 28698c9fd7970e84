#!/bin/sh
# mpi.sh NP VWALLS TEST_RADIOSITY TMPDIR LAUNCH... - `vwalls radiosity` under mpirun -np NP
# against the one-cell solution of the threads engine (Cornell box, sf 2e-4):
#  - layouts 2x2x2 and 4x4x4, 1 and 2 workers per process: area-weighted relative RMS
#    over the original polygons <= 1 %, energy ledger <= 1e-9 relative, the stats name
#    NP processes, and the outputs come from rank 0 alone (one warning line, not NP: the
#    back wall is made 3.2 mm off planar for it, as the published red wall is and as
#    `gen cornell` once wrote it);
#  - --checkpoint-every under MPI (rank 0's clock decides for all): a job stopped after a
#    checkpoint resumes under MPI to the solution; a missing checkpoint fails every rank;
#  - a closed box of Kd 1 stops, stalled, on every rank together (--stall-shots).
set -u
NP=$1 V=$2 TR=$3 T=$4
shift 4
LAUNCH="$*"
rm -rf "$T" && mkdir -p "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

"$TR" gen cornell "$T/gen.nff" || fail "gen"
# The back wall's (polygon 6) last corner, 'p 4' then 4 corners at lines 45-49.
sed '49s/^556 548.79999999999995 559.20000000000005$/556 548.79999999999995 562.4/' \
  "$T/gen.nff" >"$T/cornell.nff"
grep -q "^556 548.79999999999995 562.4$" "$T/cornell.nff" || fail "warping the back wall"
common="--sf 2e-4 --quiet"
loud="--sf 2e-4"  # summary and warnings: they must come from rank 0 alone
"$V" radiosity "$T/cornell.nff" --cells 1 --workers 1 $common --csv "$T/ref.csv" 2>/dev/null ||
  fail "one-cell threads run"

# ledger JSON NP: energy_error <= 1e-9 and engine.processes == NP
ledger() {
  python3 - "$1" "$2" <<'PY' || exit 1
import json, sys
d = json.load(open(sys.argv[1]))
e, p = d["radiosity"]["energy_error"], d["engine"]["processes"]
print(f"  energy error {e:.2e}, processes {p}, shots {d['radiosity']['shots']}, "
      f"converged {d['radiosity']['converged']}")
sys.exit(0 if e <= 1e-9 and p == int(sys.argv[2]) and d["radiosity"]["converged"] else 1)
PY
}

for cells in 2x2x2 4x4x4; do
  for w in 1 2; do
    tag="np${NP}_${cells}_w$w"
    echo "$tag:"
    $LAUNCH "$V" radiosity "$T/cornell.nff" --cells $cells --workers $w $loud \
      --csv "$T/$tag.csv" --stats "$T/$tag.json" -o "$T/$tag.ply" >"$T/$tag.out" 2>"$T/$tag.err" ||
      fail "$tag: exit $? ($(cat "$T/$tag.err"))"
    n=$(grep -c "^radiosity: converged" "$T/$tag.out")
    [ "$n" -eq 1 ] || fail "$tag: $n summaries (want 1, from rank 0)"
    "$TR" csvcmp "$T/ref.csv" "$T/$tag.csv" 0.01 || fail "$tag: differs from one cell"
    ledger "$T/$tag.json" "$NP" || fail "$tag: ledger or process count"
    n=$(grep -c "warning: polygon (id 6)" "$T/$tag.err")
    [ "$n" -eq 1 ] || fail "$tag: $n copies of the meshing warning (want 1, from rank 0)"
  done
done

# Checkpoints under MPI every 0.2 s (rank 0's clock decides for all): stop the job
# with SIGTERM once one exists (mpirun forwards it to every rank), resume under MPI.
tag="np${NP}_ck"
$LAUNCH "$V" radiosity "$T/cornell.nff" --cells 2x2x2 --workers 1 $common --csv "$T/never.csv" \
  --checkpoint "$T/ck" --checkpoint-every 0.2 2>"$T/$tag.err" &
pid=$!
i=0
while [ ! -s "$T/ck" ] && [ $i -lt 1000 ]; do sleep 0.02; i=$((i+1)); done
kill -TERM $pid 2>/dev/null
wait $pid 2>/dev/null
[ -s "$T/ck" ] || fail "$tag: no checkpoint written ($(cat "$T/$tag.err"))"
[ ! -e "$T/never.csv" ] || echo "note: the run ended before the kill"
ls "$T" | grep -q "tmp\." && fail "$tag: temporary file left behind"
$LAUNCH "$V" radiosity "$T/cornell.nff" --cells 2x2x2 --workers 1 $common --csv "$T/resumed.csv" \
  --resume "$T/ck" --stats "$T/resumed.json" 2>"$T/$tag.err" || fail "$tag: resume ($(cat "$T/$tag.err"))"
"$TR" csvcmp "$T/ref.csv" "$T/resumed.csv" 0.01 || fail "$tag: resumed differs from one cell"
ledger "$T/resumed.json" "$NP" || fail "$tag: resumed ledger"
# A checkpoint that is not there: exit 2 on every rank, no hang.
$LAUNCH "$V" radiosity "$T/cornell.nff" --cells 2x2x2 --workers 1 $common --csv "$T/x.csv" \
  --resume "$T/missing" 2>"$T/missing.err"; rc=$?
[ $rc -ne 0 ] || fail "missing checkpoint: exit 0"
grep -q "cannot open checkpoint" "$T/missing.err" || fail "missing checkpoint: $(cat "$T/missing.err")"
[ ! -e "$T/x.csv" ] || fail "missing checkpoint: output written"

# A closed box of Kd 1 (closed.sh) stalls under MPI too: the stall check is an
# agreement every --stall-shots shots (rank 0 judges by the ledger, every rank stops
# after the same round), one warning of each kind from rank 0, exit 0 on every rank.
SRC=$(dirname "$0")
cp "$SRC/closed_box.obj" "$SRC/closed_white.mtl" "$T/" || fail "closed box: copy"
tag="np${NP}_stall"
$LAUNCH "$V" radiosity "$T/closed_box.obj" --cells 2x2x2 --workers 1 --patch-size 0.5 --hemicube 16 \
  --stall-shots 1000 --max-shots 20000 --quiet --stats "$T/$tag.json" 2>"$T/$tag.err" ||
  fail "$tag: exit $? ($(cat "$T/$tag.err"))"
python3 - "$T/$tag.json" <<'PY' || fail "$tag: $(cat "$T/$tag.json")"
import json, sys
r = json.load(open(sys.argv[1]))["radiosity"]
print(f"  stalled {r['stalled']} after {r['shots']} shots, energy error {r['energy_error']:.2e}")
sys.exit(0 if r["stalled"] and not r["converged"] and 1000 <= r["shots"] < 1200
         and r["energy_error"] <= 1e-9 else 1)
PY
[ "$(grep -c "warning: stalled after" "$T/$tag.err")" -eq 1 ] &&
  [ "$(grep -c "closed_white.mtl:2: warning: material 'white': reflectance 1 1 1 of polygon (id 0, [^)]*closed_box.obj:47)" "$T/$tag.err")" -eq 1 ] ||
  fail "$tag: warnings $(cat "$T/$tag.err")"
echo "ok"
