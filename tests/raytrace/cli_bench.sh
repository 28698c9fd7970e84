#!/bin/sh
# cli_bench.sh - vwalls bench: every configuration (layouts x worker counts) renders, the
# table has a row for each in order, the first row is the reference (speedup 1), the
# images are checked identical (and a difference, forced with VW_FAULT=bench-mismatch,
# fails the command with status 1 and no CSV); no memory for the reference image stops
# every process (VW_FAULT=bench-nomem); bad options are usage errors (status 2) that
# write nothing. --stats writes the table's figures as the stats JSON, with the CSV or
# not at all.
# usage: cli_bench.sh VWALLS TMPDIR ["LAUNCHER -n 2 ..."]
set -u
V=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") T=$2 L=${3:-}
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
# shellcheck disable=SC2086
run() { $L "$V" bench "$@"; }

run --size 32x24 --repeat 2 --cells 1,2x2x2,3x1x2 --workers 1,2 --csv t.csv --stats t.json \
  > out.txt 2> err.txt
rc=$?
[ "$rc" -eq 0 ] || { cat out.txt err.txt; fail "bench: status $rc"; }
cat out.txt
grep -q '^images: identical in all 6 configurations' out.txt || fail "no 'images: identical' line"
[ "$(wc -l < t.csv)" -eq 7 ] || fail "CSV: $(wc -l < t.csv) lines, expected a header and 6 rows"
head -1 t.csv | grep -q '^cells,cell_count,workers,copies,build_s,compute_s,speedup,' ||
  fail "CSV header: $(head -1 t.csv)"
# The rows in the order given: every layout with every worker count.
got=$(sed 1d t.csv | cut -d, -f1,2 | tr '\n' ' ')
[ "$got" = "1,1 1,1 2x2x2,8 2x2x2,8 3x1x2,6 3x1x2,6 " ] || fail "CSV rows: $got"
# The first row is the reference, and a ray visits at least one cell.
sed -n 2p t.csv | awk -F, '$7 != 1 || $8 != 1 || $9 != 1 { exit 1 }' || fail "first row: $(sed -n 2p t.csv)"
sed 1d t.csv | awk -F, '$11 < 1 { exit 1 }' || fail "visits per ray below 1"
# One cell visits one cell per ray; 2x2x2 more.
sed -n 2p t.csv | awk -F, '$11 != 1 { exit 1 }' || fail "1 cell: visits per ray not 1"
sed -n 4p t.csv | awk -F, '$11 <= 1 { exit 1 }' || fail "2x2x2: visits per ray not above 1"
# The stats JSON: the same rows as the CSV, every round's times, the best of them.
python3 - t.json t.csv <<'PY' || fail "stats JSON"
import csv, json, sys
j = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
assert j["command"] == "bench" and j["version"], j
assert j["rounds"] == 2 and j["image"] == {"width": 32, "height": 24, "depth": 5}, j
assert j["images_identical"] is True and j["time_s"]["total"] > 0, j
assert j["scene"]["generator"] == "balls" and j["scene"]["spheres"] == 7381, j["scene"]
c = j["configurations"]
assert len(c) == len(rows) == 6, (len(c), len(rows))
for r, k in zip(rows, c):
    assert (r["cells"], int(r["cell_count"]), int(r["workers"])) == (k["layout"], k["cells"], k["workers"]), (r, k)
    assert len(k["compute_rounds_s"]) == 2 and k["compute_s"] == min(k["compute_rounds_s"]), k
    # lambda is a timing too: the one of the round whose compute time is given
    best = k["compute_rounds_s"].index(k["compute_s"])
    assert len(k["imbalance_rounds"]) == 2 and k["imbalance"] == k["imbalance_rounds"][best], k
    assert abs(float(r["compute_s"]) - k["compute_s"]) < 1e-6, (r, k)
    assert k["rays"] > 0 and k["segments"] >= k["rays"], k
assert c[0]["speedup"] == 1, c[0]
PY

# A configuration whose image differs: status 1, named, no CSV.
VW_FAULT=bench-mismatch run --size 16x16 --repeat 1 --cells 1,2x2x2 --workers 1 --csv m.csv \
  --stats m.json > out.txt 2> err.txt
rc=$?
[ "$rc" -eq 1 ] || { cat out.txt err.txt; fail "mismatch: status $rc, expected 1"; }
grep -q 'vwalls bench: cells 2x2x2 on 1 worker rendered another image than the first configuration' err.txt ||
  { cat err.txt; fail "mismatch: no message"; }
[ ! -e m.csv ] && [ ! -e m.json ] || fail "mismatch: the CSV or the stats were written"

# No memory for the reference image, which the output process alone keeps: every
# process stops (under MPI the others used to wait for it in the next render).
# shellcheck disable=SC2086
VW_FAULT=bench-nomem timeout 60 $L "$V" bench --size 16x16 --repeat 1 --cells 1,2 --workers 1 \
  --csv n.csv > out.txt 2> err.txt
rc=$?
[ "$rc" -eq 1 ] || { cat out.txt err.txt; fail "no memory: status $rc, expected 1"; }
grep -q 'out of memory for the reference image' err.txt || { cat err.txt; fail "no memory: no message"; }
[ ! -e n.csv ] || fail "no memory: the CSV was written"

# Usage errors: status 2, a message, nothing written.
for bad in "--cells 1,,2" "--cells 0" "--cells ," "--workers 0" "--workers 1,x" "--repeat 0" \
           "--repeat 101" "--size 0x4" "--depth 65" "--farm most" "--bogus" "a.nff b.nff" \
           "missing.nff"; do
  # shellcheck disable=SC2086
  run $bad --csv u.csv --stats u.json > out.txt 2> err.txt
  rc=$?
  [ "$rc" -eq 2 ] || { cat out.txt err.txt; fail "bench $bad: status $rc, expected 2"; }
  [ -s err.txt ] || fail "bench $bad: no message"
  [ ! -e u.csv ] && [ ! -e u.json ] || fail "bench $bad: the CSV or the stats were written"
done
# The stats cannot be written: no CSV either.
run --size 16x16 --repeat 1 --cells 1 --workers 1 --csv f.csv --stats /dev/full > out.txt 2> err.txt
[ $? -eq 1 ] && grep -q '/dev/full' err.txt || { cat err.txt; fail "--stats /dev/full: not a failure"; }
[ ! -e f.csv ] || fail "--stats /dev/full: the CSV was written"
# More configurations than the table takes.
run --cells 1,2,3,4,5,6,7,8,9 --workers 1,2,3,4,5,6,7,8 > out.txt 2> err.txt
[ $? -eq 2 ] && grep -q '72 configurations' err.txt || { cat err.txt; fail "72 configurations accepted"; }
echo ok
