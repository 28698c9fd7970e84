#!/bin/sh
# default_block.sh - vwalls render without --map maps the cells as --map block does, as
# docs/balancing.md and the stats ("map": "block") say. Until the twenty-eighth session
# the world's own runs of cell ids were used: 4x4x1 cells on 4 workers went 0,0,0,0,
# 1,1,1,1, ... (7143 messages between workers at 96x96) where block gives 2x2 squares
# (3873). The image is the same either way.
# usage: default_block.sh VWALLS TMPDIR
set -u
V=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$V" gen spheres --count 300 -o s.nff || fail "gen"
for m in default block; do
  opt=""
  [ "$m" = block ] && opt="--map block"
  # shellcheck disable=SC2086
  "$V" render s.nff -o "$m.png" --size 48x48 --cells 4x4x1 --workers 4 --farm none $opt \
    --stats "$m.json" -q || fail "render ($m): status $?"
done
cmp -s default.png block.png || fail "the images differ"
python3 - default.json block.json <<'PY' || fail "the default mapping is not block's"
import json, sys
d, b = (json.load(open(f)) for f in sys.argv[1:3])
wd = [c["worker"] for c in d["cells"]]
wb = [c["worker"] for c in b["cells"]]
print("default:", wd)
print("block:  ", wb)
assert wd == wb, "cells' workers differ"
assert d["balance_detail"]["map"] == "block", d["balance_detail"]["map"]
assert d["traffic"]["messages"] == b["traffic"]["messages"], (d["traffic"], b["traffic"])
PY
echo "ok"
