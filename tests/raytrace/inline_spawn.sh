#!/bin/sh
# inline_spawn.sh - the ray tracer sends no message to its own worker: a ray crossing a
# wall into a cell of the same worker is handed on inline (vw_ctx_enter), and so, since
# the twenty-eighth session, is a new ray whose walk starts in the next cell (from a hit
# just past the wall, within the overlap), which was sent: 4 messages on 2x2x2 and 4x4x4
# over 3 workers at 96x96 (traffic.worker_messages). The image stays the same.
# usage: inline_spawn.sh VWALLS TMPDIR
set -u
V=$(cd "$(dirname "$1")" && pwd)/$(basename "$1") T=$2
rm -rf "$T" && mkdir -p "$T" && cd "$T" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
"$V" gen balls -o b.nff || fail "gen"
"$V" render b.nff -o one.png --size 96x96 --cells 1 --workers 1 -q || fail "render 1 cell"
for c in 2x2x2 4x4x4; do
  "$V" render b.nff -o "$c.png" --size 96x96 --cells "$c" --workers 3 --farm none \
    --stats "$c.json" -q || fail "render $c: status $?"
  cmp -s one.png "$c.png" || fail "$c: the image differs from one cell's"
  n=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["traffic"]["worker_messages"])' "$c.json")
  echo "$c on 3 workers: $n messages to the sender's own worker"
  [ "$n" = 0 ] || fail "$c: $n messages to the sender's own worker, expected 0"
done
echo "ok"
