#!/bin/sh
# bench.sh - vwalls bench says, and checks, that every configuration traced the same
# rays (what makes the rows' visits per ray comparable, as the same image needs): the
# table's footer names the count, equal to every row's "rays" in the stats; a
# configuration that traced another number (forced with VW_FAULT=bench-rays) fails the
# command with status 1, named, and no CSV or stats. (tests/raytrace/cli_bench.sh
# checks the rest of the table.)
# usage: bench.sh VWALLS TMPDIR ["LAUNCHER -n 2 ..."]
set -u
V=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") T=$2 L=${3:-}
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
# shellcheck disable=SC2086
run() { $L "$V" bench "$@"; }

run --size 24x16 --repeat 1 --cells 1,2x2x2,1x1x8 --workers 1,2 --stats t.json > out.txt 2> err.txt
rc=$?
[ "$rc" -eq 0 ] || { cat out.txt err.txt; fail "bench: status $rc"; }
cat out.txt
rays=$(sed -n 's/^rays: \([0-9][0-9]*\) in every configuration.*/\1/p' out.txt)
[ -n "$rays" ] || fail "no 'rays: N in every configuration' line"
python3 - t.json "$rays" <<'PY' || fail "stats: rows' rays differ from the footer's"
import json, sys
j = json.load(open(sys.argv[1]))
assert [c["rays"] for c in j["configurations"]] == [int(sys.argv[2])] * 6, j["configurations"]
PY

VW_FAULT=bench-rays run --size 16x16 --repeat 1 --cells 1,2 --workers 1 --csv m.csv --stats m.json \
  > out.txt 2> err.txt
rc=$?
[ "$rc" -eq 1 ] || { cat out.txt err.txt; fail "rays differ: status $rc, expected 1"; }
grep -q 'vwalls bench: cells 2 on 1 worker traced [0-9]* rays, the first configuration [0-9]*' err.txt ||
  { cat err.txt; fail "rays differ: no message"; }
[ ! -e m.csv ] && [ ! -e m.json ] || fail "rays differ: the CSV or the stats were written"
grep -q '^rays: ' out.txt && fail "rays differ, and the footer says they are the same"
echo ok
