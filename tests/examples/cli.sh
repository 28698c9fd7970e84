#!/bin/sh
# cli.sh - the example commands as a user meets them: --help on stdout (status 0); the
# result on stdout and nothing else there with --quiet, messages on stderr; a bad option
# is "vwalls CMD: message" on stderr, status 2, nothing on stdout and no stats file;
# --stats holds the printed result (counters.pairs, components.count); a --check that
# fails (forced with VW_FAULT=example-mismatch) is status 1, named, with no stats file
# left behind (the stats used to be written before the check).
# usage: cli.sh VWALLS TMPDIR
set -u
V=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }

for c in example-pairs example-components; do
  "$V" $c --help > out.txt 2> err.txt || fail "$c --help: status $?"
  grep -q "^usage: vwalls $c" out.txt || fail "$c --help: no usage on stdout"
  grep -q "sum of their radii" out.txt || fail "$c --help: does not say what touching means"
  [ ! -s err.txt ] || fail "$c --help: wrote on stderr: $(cat err.txt)"

  # --quiet: the number alone on stdout, nothing on stderr.
  "$V" $c --spheres 1500 --radius 0.04 --cells 2x2x2 --workers 2 --quiet --check \
    --stats q.json > out.txt 2> err.txt || { cat err.txt; fail "$c --quiet: status $?"; }
  grep -qx '[0-9][0-9]*' out.txt && [ "$(wc -l < out.txt)" -eq 1 ] ||
    fail "$c --quiet: stdout is not one number: $(cat out.txt)"
  [ ! -s err.txt ] || fail "$c --quiet: wrote on stderr: $(cat err.txt)"
  python3 - q.json "$(cat out.txt)" "$c" <<'PY' || fail "$c --stats: not the printed result"
import json, sys
j = json.load(open(sys.argv[1]))
n, cmd = int(sys.argv[2]), sys.argv[3]
assert j["command"] == cmd, j["command"]
assert j["decomposition"]["layout"] == "2x2x2" and j["objects"] == 1500, j
got = j["counters"]["pairs"] if cmd == "example-pairs" else j["components"]["count"]
assert got == n, (got, n)
PY

  # Bad options: status 2, one message on stderr naming the command, nothing else.
  for bad in "--cells 2x" "--radius 0" "--radius 0.3" "--spheres -1" "--spheres 12x" \
             "--workers 0" "--seed -1" "--bogus" "scene.nff" "--stats" "--stats --quiet"; do
    # shellcheck disable=SC2086
    "$V" $c $bad --stats b.json > out.txt 2> err.txt
    rc=$?
    [ "$rc" -eq 2 ] || fail "$c $bad: status $rc, expected 2"
    [ ! -s out.txt ] || fail "$c $bad: wrote on stdout: $(cat out.txt)"
    [ "$(wc -l < err.txt)" -eq 1 ] && grep -q "^vwalls $c: " err.txt ||
      fail "$c $bad: message: $(cat err.txt)"
    [ ! -e b.json ] || fail "$c $bad: the stats were written"
  done

  # A check that fails: status 1, said on stderr, no stats file.
  VW_FAULT=example-mismatch "$V" $c --spheres 500 --radius 0.04 --check --quiet \
    --stats m.json > out.txt 2> err.txt
  rc=$?
  [ "$rc" -eq 1 ] || { cat err.txt; fail "$c: a failed check: status $rc, expected 1"; }
  grep -q "^vwalls $c: distributed .* differs" err.txt || fail "$c: a failed check: $(cat err.txt)"
  [ ! -e m.json ] || fail "$c: a failed check left its stats file"
done
echo ok
