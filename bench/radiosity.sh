#!/bin/sh
# radiosity.sh [BUILD_DIR] [OUT_DIR] - benchmark of `vwalls radiosity` on the furnished
# room meshed into about 3600 patches: time to convergence on 1 and 2 workers (speedup),
# bytes per shot against shipping the geometry, unshot power against time (gnuplot),
# and the full-matrix Gauss-Seidel reference on the same hemicube form factors (one
# cell; dense matrix, ~100 MB for the room): its time, and the progressive solution's
# area-weighted relative RMS over polygons against it (GS=0 skips it). PAIRS (default 3)
# interleaved 1- and 2-worker solves give the speedup as a median.
# Not run by ctest: timings belong here, never in tests.
set -eu
B=${1:-${VW_BUILD_DIR:-$(dirname "$0")/../build}}
O=${2:-/tmp/vwalls-bench-radiosity}
V=$B/vwalls
for x in "$V" "$B/test_radiosity"; do
  [ -x "$x" ] || { echo "radiosity.sh: no $x (build first: ./run build)" >&2; exit 1; }
done
mkdir -p "$O"
"$B/test_radiosity" gen room "$O/room.nff"
SF=${SF:-1e-4}
PS=${PS:-0.21}
CELLS=${CELLS:-2x2x2}
# PAIRS interleaved 1-worker / 2-worker solves (default 3): on a shared machine one
# pair's ratio says little; the median of the pairs' ratios is reported too. The files
# of the last pair are the ones described below.
PAIRS=${PAIRS:-3}
echo "scene: room, patch size $PS, cells $CELLS, sf $SF, $PAIRS pair(s)"
: > "$O/pairs.txt"
for p in $(seq "$PAIRS"); do
  for w in 1 2; do
    "$V" radiosity "$O/room.nff" --patch-size "$PS" --cells "$CELLS" --workers $w --sf "$SF" \
         --stats "$O/w$w.json" --trace "$O/w$w.tsv" -o "$O/w$w.ply" --image "$O/w$w.png" --csv "$O/w$w.csv" --quiet
  done
  python3 -c "import json; print(json.load(open('$O/w1.json'))['time_s']['compute'] / json.load(open('$O/w2.json'))['time_s']['compute'])" >> "$O/pairs.txt"
done
GS=${GS:-1}
if [ "$GS" = 1 ]; then
  # The same meshing on one cell (pieces = the progressive solver's shooters).
  # CPU seconds too (/usr/bin/time): on a shared machine wall time says little.
  cpu() { f=$1; shift; if [ -x /usr/bin/time ]; then /usr/bin/time -f "%U %S" -o "$f" "$@"; else "$@"; fi; }
  cpu "$O/c1.cpu" "$V" radiosity "$O/room.nff" --patch-size "$PS" --cells 1 --workers 1 --sf "$SF" \
       --stats "$O/c1.json" --csv "$O/c1.csv" --quiet
  cpu "$O/gs.cpu" "$B/test_radiosity" reference "$O/room.nff" "$O/gs.csv" "$PS" 64 2 > "$O/gs.json"
fi
python3 - "$O" <<'PY'
import json, sys
o = sys.argv[1]
r = {w: json.load(open(f"{o}/w{w}.json")) for w in (1, 2)}
for w in (1, 2):
    d = r[w]; rad = d["radiosity"]; t = d["time_s"]
    print(f"workers {w}: compute {t['compute']:.3f} s (load {t['load']:.3f}, build {t['build']:.3f}), "
          f"shots {rad['shots']}, pieces {rad['pieces']}, elements {rad['elements']}, "
          f"energy error {rad['energy_error']:.2e}, imbalance {d['balance'].get('imbalance_before', 0)}")
pairs = sorted(float(x) for x in open(f"{o}/pairs.txt").read().split())
med = pairs[len(pairs) // 2] if len(pairs) % 2 else (pairs[len(pairs) // 2 - 1] + pairs[len(pairs) // 2]) / 2
print(f"speedup 2 vs 1 worker (compute), per interleaved pair: {' '.join(f'{x:.2f}' for x in pairs)}; "
      f"median {med:.2f}")
rad = r[2]["radiosity"]
per_shot = rad["shot_bytes"] / max(rad["shots"], 1)
# Shipping geometry instead: every cell would need every other cell's pieces once
# (a piece record is ~700 bytes; its vertices alone 3 doubles x ~5).
cells = r[2]["decomposition"]["cells"]
geo_vertices = rad["pieces"] * 5 * 24
print(f"bitmap bytes per shot {per_shot:.0f} ({rad['shot_messages']} messages, {rad['shot_bytes']} bytes in all)")
print(f"shipping the pieces' vertices to every other cell once: {geo_vertices * (cells - 1)} bytes "
      f"({geo_vertices} bytes of vertices x {cells - 1} cells)")
import os
if os.path.exists(f"{o}/gs.json"):
    def polys(path):
        rows = [l.split(",") for l in open(path).read().split("\n")[1:] if l]
        return {int(r[0]): (float(r[1]), [float(x) for x in r[8:11]]) for r in rows}
    def rms(a, ref):
        num = sum(ref[i][0] * (a[i][1][k] - ref[i][1][k]) ** 2 for i in ref for k in range(3))
        den = sum(ref[i][0] * ref[i][1][k] ** 2 for i in ref for k in range(3))
        return (num / den) ** 0.5
    def cpu(name):
        try:
            u, sy = open(f"{o}/{name}.cpu").read().split()[:2]
            return f", {float(u) + float(sy):.2f} s CPU for the whole command"
        except (OSError, ValueError):
            return ""
    g = json.load(open(f"{o}/gs.json"))
    ref = polys(f"{o}/gs.csv")
    print(f"Gauss-Seidel reference: {g['patches']} patches, matrix {g['matrix_bytes'] / 1e6:.0f} MB, "
          f"form factors {g['form_factors_s']:.2f} s + Gauss-Seidel {g['gauss_seidel_s']:.2f} s "
          f"({g['sweeps']} sweeps, last change {g['change']:.1e} of emitted), 1 thread{cpu('gs')}")
    c1 = json.load(open(f"{o}/c1.json"))
    print(f"progressive, 1 cell, 1 worker, sf {c1['radiosity']['sf']:g}: compute {c1['time_s']['compute']:.2f} s, "
          f"{c1['radiosity']['shots']} shots, relative RMS vs Gauss-Seidel {100 * rms(polys(o + '/c1.csv'), ref):.3f}%{cpu('c1')}")
    for w in (1, 2):
        print(f"progressive, {r[w]['decomposition']['layout']}, {w} worker(s): compute {r[w]['time_s']['compute']:.2f} s, "
              f"relative RMS vs Gauss-Seidel {100 * rms(polys(f'{o}/w{w}.csv'), ref):.3f}%")
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
