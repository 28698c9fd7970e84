#!/bin/sh
# radiosity.sh [BUILD_DIR] [OUT_DIR] - benchmark of `vwalls radiosity` on the furnished
# room meshed into about 3600 patches: time to convergence on 1 and 2 workers (speedup),
# bytes per shot against shipping the geometry, and unshot power against time (gnuplot).
# Not run by ctest: timings belong here, never in tests.
set -eu
B=${1:-$(dirname "$0")/../build-rad}
O=${2:-/tmp/vwalls-bench-radiosity}
V=$B/vwalls
mkdir -p "$O"
"$B/test_radiosity" gen room "$O/room.nff"
SF=${SF:-1e-4}
PS=${PS:-0.21}
CELLS=${CELLS:-2x2x2}
echo "scene: room, patch size $PS, cells $CELLS, sf $SF"
for w in 1 2; do
  "$V" radiosity "$O/room.nff" --patch-size "$PS" --cells "$CELLS" --workers $w --sf "$SF" \
       --stats "$O/w$w.json" --trace "$O/w$w.tsv" -o "$O/w$w.ply" --image "$O/w$w.png" --quiet
done
python3 - "$O" <<'PY'
import json, sys
o = sys.argv[1]
r = {w: json.load(open(f"{o}/w{w}.json")) for w in (1, 2)}
for w in (1, 2):
    d = r[w]; rad = d["radiosity"]; t = d["time_s"]
    print(f"workers {w}: compute {t['compute']:.3f} s (load {t['load']:.3f}, build {t['build']:.3f}), "
          f"shots {rad['shots']}, pieces {rad['pieces']}, elements {rad['elements']}, "
          f"energy error {rad['energy_error']:.2e}, imbalance {d['balance'].get('imbalance_before', 0)}")
print(f"speedup 2 vs 1 worker: {r[1]['time_s']['compute'] / r[2]['time_s']['compute']:.2f}")
rad = r[2]["radiosity"]
per_shot = rad["shot_bytes"] / max(rad["shots"], 1)
# Shipping geometry instead: every cell would need every other cell's pieces once
# (a piece record is ~700 bytes; its vertices alone 3 doubles x ~5).
cells = r[2]["decomposition"]["cells"]
geo_vertices = rad["pieces"] * 5 * 24
print(f"bitmap bytes per shot {per_shot:.0f} ({rad['shot_messages']} messages, {rad['shot_bytes']} bytes in all)")
print(f"shipping the pieces' vertices to every other cell once: {geo_vertices * (cells - 1)} bytes "
      f"({geo_vertices} bytes of vertices x {cells - 1} cells)")
PY
if command -v gnuplot >/dev/null; then
  gnuplot <<GP
set terminal pngcairo size 800,500 noenhanced
set output "$O/unshot.png"
set logscale y
set xlabel "seconds"
set ylabel "max unshot power / emitted"
set title "vwalls radiosity, room ($CELLS cells)"
plot "$O/w1.tsv" using 1:3 with linespoints title "1 worker", \
     "$O/w2.tsv" using 1:3 with linespoints title "2 workers", $SF title "sf"
GP
  echo "plot: $O/unshot.png"
fi
