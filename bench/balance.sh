#!/usr/bin/env bash
# bench/balance.sh - the four Virtual Walls balancing strategies side by side: lambda
# (max/mean) and efficiency 1/lambda of the counted work (ray-cell visits, one worker per
# cell: deterministic) and of busy time (2 workers), for uniform, 50% and 100% clustered
# 1000-sphere scenes and an oblique line of spheres, at 8, 16 and 64 cells; speedup of
# the compute phase over no balancing with 2 workers; a cluster moving over 20 frames
# (vwalls animate, rebalanced between frames); and a picture of the walls before and
# after for the clustered scene. Usage: bench/balance.sh [OUTDIR] (default
# bench/out/balance); VW_BUILD_DIR picks the build; SIZE=WxH (default 256x256).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
OUT=${1:-$(dirname "${BASH_SOURCE[0]}")/out/balance}
SIZE=${SIZE:-256x256}
mkdir -p "$OUT"
# Scratch (the rendered images, each run's stats, the frames) goes to T, removed at exit.
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

"$VWALLS" gen spheres --count 1000 --seed 7 -o "$OUT/uniform.nff"
"$VWALLS" gen spheres --count 1000 --cluster 0.5 --seed 7 -o "$OUT/cluster50.nff"
"$VWALLS" gen spheres --count 1000 --cluster 1 --seed 7 -o "$OUT/cluster100.nff"
# An oblique line of 400 spheres from one corner of the box to the other, seen from the side.
awk -f "$(dirname "${BASH_SOURCE[0]}")/oblique.awk" > "$OUT/oblique.nff"

# json FILE KEY...: numbers from the stats JSON (python3 reads it).
json() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); print(' '.join(str(eval('d'+k)) for k in sys.argv[2:]))" "$@"; }

layout() { case $1 in 8) echo 2x2x2 ;; 16) echo 4x2x2 ;; 64) echo 4x4x4 ;; esac; }

TABLE="$OUT/table.md"
{
  echo "| scene | cells | strategy | λ work | 1/λ work | λ busy (2 w) | 1/λ busy | compute s (2 w) | speedup | migrated | max nb |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
} > "$TABLE"
# The generated sphere scenes fill the cube [0,10]^3 (their cluster lies in one octant):
# the walls divide that space, as the paper's grids do (--world), not the objects' own
# bounds, which would cut a full cluster evenly. The oblique line runs corner to corner.
world() { case $1 in oblique) ;; *) echo --world 0,0,0,10,10,10 ;; esac; }
for scene in uniform cluster50 cluster100 oblique; do
  for cells in 8 16 64; do
    L=$(layout $cells)
    read -r -a W <<< "$(world "$scene")"
    base=""
    for s in none tensor rotate staggered divide duplicate; do
      # Deterministic: one worker per cell, loads = counted ray-cell visits (none has
      # no pre-pass to count them in: its counted work is the render's).
      bl=(--balance-load segments)
      [ "$s" = none ] && bl=()
      "$VWALLS" render "$OUT/$scene.nff" -o "$T/img.png" --size "$SIZE" --cells "$L" \
        --workers "$cells" --farm none --balance "$s" "${bl[@]}" "${W[@]}" --quiet \
        --stats "$T/w.json"
      read -r lw mig nb < <(json "$T/w.json" "['balance_detail']['imbalance_work']" \
        "['balance_detail']['migrated_objects']" "['balance_detail']['max_neighbours']")
      # Measured: 2 workers, loads = busy time; best compute time of 3.
      best=""; lb=""
      for _ in 1 2 3; do
        "$VWALLS" render "$OUT/$scene.nff" -o "$T/img.png" --size "$SIZE" --cells "$L" \
          --workers 2 --farm none --balance "$s" "${W[@]}" --quiet --stats "$T/b.json"
        read -r c l < <(json "$T/b.json" "['time_s']['compute']" "['balance']['imbalance']")
        if [ -z "$best" ] || awk -v a="$c" -v b="$best" 'BEGIN { exit !(a < b) }'; then best=$c; lb=$l; fi
      done
      [ "$s" = none ] && base=$best
      printf "| %s | %s | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %s | %s | %s |\n" "$scene" "$L" "$s" \
        "$lw" "$(awk -v x="$lw" 'BEGIN{print 1/x}')" "$lb" "$(awk -v x="$lb" 'BEGIN{print 1/x}')" \
        "$best" "$(ratio "$base" "$best")" "$mig" "$nb" | tee -a "$TABLE"
    done
  done
done

# A moving cluster over 20 frames (vwalls animate): 600 spheres spread over the box and a
# cluster of 400 that travels along x from one side to the other; between frames the
# balancer runs on the last frame's counted work when that work's lambda exceeds 1.1
# (--trigger work). 8 cells, 8 workers on 2 cores: the per-frame busy-time lambda is
# noise; the counted work's (ray segments per worker), and so the rebalances, are the
# same on every run.
awk 'BEGIN {
  print "v\nfrom 0.5 -2.2 0.9\nat 0.5 0.5 0.5\nup 0 0 1\nangle 35\nhither 0.01\nresolution 160 160";
  print "b 0.1 0.1 0.1\nl 2 -3 3\nl -1 -2 2\nf 0.8 0.8 0.8 0.8 0.2 10 0 1";
  srand(11);
  for (i = 0; i < 600; i++) printf "s %.4f %.4f %.4f 0.012\n", rand(), rand(), rand();
  for (i = 0; i < 400; i++) {
    do { x = 2 * rand() - 1; y = 2 * rand() - 1; z = 2 * rand() - 1 } while (x*x + y*y + z*z > 1);
    printf "s %.4f %.4f %.4f 0.012\n", 0.12 + 0.1 * x, 0.5 + 0.1 * y, 0.5 + 0.1 * z;
  }
}' > "$OUT/moving.nff"
{ echo "check off"; echo "frame"
  for f in $(seq 1 19); do
    for i in $(seq 600 999); do echo "move $i 0.04 0 0"; done
    echo "frame"
  done; } > "$OUT/moving.edits"
MOVING="$OUT/moving.md"
{ echo "| moving cluster, 20 frames, 2x2x2, 8 workers | λ work mean | λ work max | λ work last 10 mean | λ busy mean | λ busy max | rebalances |"
  echo "|---|---|---|---|---|---|---|"; } > "$MOVING"
for s in none tensor staggered divide; do
  mkdir -p "$T/frames"
  "$VWALLS" animate "$OUT/moving.nff" "$OUT/moving.edits" -o "$T/frames/$s-%04d.png" --cells 2x2x2 \
    --workers 8 --balance "$s" --trigger work --quiet --stats "$T/anim.json"
  python3 - "$T/anim.json" "$s" >> "$MOVING" <<'PY'
import json, sys
fr = json.load(open(sys.argv[1]))["animation"]["per_frame"]
lam = [f["lambda"] for f in fr]
work = [f["work_lambda"] for f in fr]
print("| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %d |" % (sys.argv[2], sum(work) / len(work), max(work),
      sum(work[10:]) / len(work[10:]), sum(lam) / len(lam), max(lam), sum(f["balanced"] for f in fr)))
PY
done
cat "$MOVING"

# Walls before and after for the 50% clustered scene (8 cells, staggered), and the
# mapping of 16 cells onto 2 workers.
"$VWALLS" render "$OUT/cluster50.nff" -o "$T/img.png" --size 384x384 --cells 2x2x2 --workers 8 \
  --farm none --world 0,0,0,10,10,10 --quiet --overlay "$OUT/walls_before.png"
"$VWALLS" render "$OUT/cluster50.nff" -o "$T/img.png" --size 384x384 --cells 2x2x2 --workers 8 \
  --balance staggered --balance-load segments --world 0,0,0,10,10,10 --quiet --overlay "$OUT/walls_staggered.png"
"$VWALLS" render "$OUT/cluster50.nff" -o "$T/img.png" --size 384x384 --cells 2x2x2 --workers 8 \
  --balance tensor --balance-load segments --world 0,0,0,10,10,10 --quiet --overlay "$OUT/walls_tensor.png"
# The side-by-side picture is an extra: a convert that cannot make it (ImageMagick
# missing, or a stand-in of that name) leaves the three pictures, not a failed bench.
if command -v convert >/dev/null &&
   ! convert "$OUT/walls_before.png" "$OUT/walls_tensor.png" "$OUT/walls_staggered.png" \
       +append "$OUT/walls_before_after.png" 2>/dev/null; then
  echo "no walls_before_after.png: convert failed (ImageMagick: apt-get install imagemagick)" >&2
fi
echo "table: $TABLE"
