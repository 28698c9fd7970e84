#!/usr/bin/env bash
# bench/dynamic.sh - the dynamic-scene handler: FRAMES frames, each moving FRAC of N
# random spheres (vwalls gen spheres) by a small random step with collision and sweep
# tests on; time per frame of the incremental update (only the cells a moved sphere left
# or joined rebuild their Embree scene) against a full rebuild of every cell, each with
# and without rebalancing between frames (tensor), and lambda per frame.
# Phases per frame (means over frames 1..FRAMES-1, from the stats JSON):
#   decide = the distributed collision/sweep query of the frame's moves,
#   update = vw_world_update_object in both worlds, build = commit (cell rebuilds),
#   render = the ray-traced frame; cells = cells rebuilt (incremental: those a moved
#   sphere left or joined; all CELLS with --full-rebuild and after a rebalance).
set -euo pipefail
. "$(dirname "$0")/lib.sh"
N=${N:-10000}
FRAMES=${FRAMES:-50}
FRAC=${FRAC:-0.1}
CELLS=${CELLS:-4x4x2}
WORKERS=${WORKERS:-2}
SIZE=${SIZE:-256x256}
OUT=${OUT:-$(mktemp -d /tmp/vw-dynamic.XXXXXX)}
mkdir -p "$OUT"

"$VWALLS" gen spheres --count "$N" --seed 7 --cluster 0.5 -o "$OUT/scene.nff"
# The script: sweep on; per frame FRAC*N distinct random spheres, steps of up to 2% of
# the scene size (the spheres scene spans about 1 unit; read the bounds from info).
read -r lo hi < <("$VWALLS" info "$OUT/scene.nff" | awk '/^bounds:/ { print $2, $5 }')
python3 - "$N" "$FRAMES" "$FRAC" "$lo" "$hi" > "$OUT/edits.txt" <<'PY'
import random, sys
n, frames, frac, lo, hi = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
step = 0.02 * (hi - lo)
rnd = random.Random(1994)
print("check on\nsweep on")
for f in range(frames):
    for i in rnd.sample(range(n), int(frac * n)):
        print("move %d %.6g %.6g %.6g" % (i, rnd.uniform(-step, step), rnd.uniform(-step, step), rnd.uniform(-step, step)))
    print("frame")
PY

# --farm idle in every run: the cells stay mapped onto the workers, as with --balance
# (whose runs farm only idle workers), so lambda and the render times compare.
run() { # name args...
  local name=$1; shift
  "$VWALLS" animate "$OUT/scene.nff" "$OUT/edits.txt" -o "$OUT/$name-%04d.png" --cells "$CELLS" \
    --workers "$WORKERS" --size "$SIZE" --quiet --keep-going --farm idle --stats "$OUT/$name.json" "$@"
  python3 - "$OUT/$name.json" "$name" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
fr = s["animation"]["per_frame"][1:]  # frame 0 has no edits
m = lambda k: sum(f[k] for f in fr) / len(fr)
lam = [f["lambda"] for f in s["animation"]["per_frame"]]
acc = sum(f["accepted"] for f in fr); ed = sum(f["edits"] for f in fr)
print("%-20s decide %7.4f  update %7.4f  build %7.4f  render %7.4f  frame %7.4f s  cells %6.1f  "
      "accepted %5.1f%%  lambda mean %.3f max %.3f  rebalances %d"
      % (sys.argv[2], m("decide_s"), m("update_s"), m("build_s"), m("render_s"),
         m("decide_s") + m("update_s") + m("build_s") + m("render_s"), m("cells_rebuilt"),
         100.0 * acc / max(ed, 1), sum(lam) / len(lam), max(lam), sum(f["balanced"] for f in fr)))
print("  lambda per frame:", " ".join("%.2f" % l for l in lam))
PY
}

echo "N=$N spheres, $FRAMES frames, $FRAC moved per frame, cells $CELLS, workers $WORKERS, $SIZE"
run incremental
run full-rebuild --full-rebuild
run incremental-tensor --balance tensor
run full-tensor --full-rebuild --balance tensor
# Few moves per frame (10 spheres): here the incremental update rebuilds only the few
# cells they touch, where 10% of the spheres touch nearly every cell.
python3 - "$N" "$FRAMES" 10 "$lo" "$hi" > "$OUT/edits-small.txt" <<'PY'
import random, sys
n, frames, k, lo, hi = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
step = 0.02 * (hi - lo)
rnd = random.Random(5)
print("check on\nsweep on")
for f in range(frames):
    for i in rnd.sample(range(n), k):
        print("move %d %.6g %.6g %.6g" % (i, rnd.uniform(-step, step), rnd.uniform(-step, step), rnd.uniform(-step, step)))
    print("frame")
PY
cp "$OUT/edits.txt" "$OUT/edits-many.txt"
cp "$OUT/edits-small.txt" "$OUT/edits.txt"
run small-incremental
run small-full-rebuild --full-rebuild
cp "$OUT/edits-many.txt" "$OUT/edits.txt"
# The images must not depend on how the cells were rebuilt or balanced.
for f in 0001 $(printf '%04d' $((FRAMES / 2))) $(printf '%04d' $((FRAMES - 1))); do
  [ -e "$OUT/incremental-$f.png" ] || continue
  cmp -s "$OUT/incremental-$f.png" "$OUT/full-rebuild-$f.png" || echo "frame $f differs (full rebuild)!"
  cmp -s "$OUT/incremental-$f.png" "$OUT/incremental-tensor-$f.png" || echo "frame $f differs (tensor)!"
done
echo "frames and stats in $OUT"
