#!/usr/bin/env bash
# plots.sh - the experiment's pictures, from results.csv and the radiosity traces in OUT:
#   efficiency.png  against the number of cells (threads engine, one cell per worker):
#                   measured efficiency (bounded by cores / workers on this machine), the
#                   load-balance efficiency 1/lambda of the counted work (busy time on
#                   more workers than cores is mostly waiting for a core), and the model
#                   efficiency from
#                   counted work, without and (dashed) with balancing where available
#   unshot.png      radiosity: max unshot power / emitted against seconds, per layout
#   speedup.png     compute-phase speedup against cells, with the machine's core count
#   usage: plots.sh OUT
set -euo pipefail
OUT=$1
D=$OUT/plotdata
mkdir -p "$D"
rm -f "$D"/*.dat
# one data file per (app, clustering, balance) of threads rows with one cell per worker,
# the mean over the sphere counts (100, 500, 1000) so the plot keeps a readable handful of
# lines; per scene figures are in the table: cells efficiency 1/lambda_work speedup eff_model
awk -F, -v d="$D" 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  $(c["engine"]) == "threads" && $(c["workers"]) == $(c["cells"]) {
    sc = $(c["scene"]); sub(/^s[0-9]+-c/, "", sc)
    if ($(c["app"]) == "raytrace") sc = "spheres " (sc * 100) "% clustered"
    k = $(c["app"]) "_" sc "_" $(c["balance"]) SUBSEP $(c["cells"])
    e[k] += $(c["efficiency"]); l[k] += ($(c["lambda_work"]) > 0 ? 1 / $(c["lambda_work"]) : 0); s[k] += $(c["speedup"]); m[k] += $(c["eff_model"]); n[k]++
  }
  END { for (k in n) { split(k, a, SUBSEP); f = d "/" a[1] ".dat"; gsub(/ /, "-", f)
          printf "%d %.4f %.4f %.4f %.4f\n", a[2], e[k] / n[k], l[k] / n[k], s[k] / n[k], m[k] / n[k] >> f } }' "$OUT/results.csv"
for f in "$D"/*.dat; do sort -n -o "$f" "$f"; done

NPROC=$(nproc 2>/dev/null || echo 1)
plotlist() { # plotlist COLUMN: a gnuplot plot list over the data files
  local col=$1 first=1 f name dt lt=0 bal
  for f in "$D"/*.dat; do
    [ "$(wc -l < "$f")" -gt 1 ] || continue    # a strategy tried on one layout only
    name=$(basename "$f" .dat)
    bal=${name##*_}
    [ "$bal" = none ] && { lt=$((lt + 1)); dt=1; } || dt=2
    [ $first = 1 ] || printf ', '
    first=0
    t=${name//_/ }
    printf '"%s" using 1:%s with linespoints lw 2 lc %d dt %d pt %d title "%s"' "$f" "$col" "$lt" "$dt" "$((lt % 13 + 1))" "${t//-/ }"
  done
}

gnuplot <<GP
set terminal pngcairo size 1500,540 noenhanced
set output "$OUT/efficiency.png"
set multiplot layout 1,3 title "vwalls: one cell per worker (threads engine), $NPROC cores; ray tracing: mean over 100, 500, 1000 spheres"
set xlabel "cells (= workers)"
set xtics (1, 2, 4, 6, 8)
set key bottom left font ",8"
set grid
set yrange [0:1.1]
set title "measured efficiency = speedup / workers"
set key top right font ",8"
plot $(plotlist 2), $NPROC / x with lines lc rgb "black" dt 2 title "cores / workers"
set key bottom left font ",8"
set title "load-balance efficiency 1/lambda of counted work (dashed: balanced)"
plot $(plotlist 3)
set title "model: (seq. work / work) / lambda of counted work"
plot $(plotlist 5)
unset multiplot

set terminal pngcairo size 800,520 noenhanced
set output "$OUT/speedup.png"
set title "compute-phase speedup against 1 cell on 1 worker ($NPROC cores)"
set yrange [0:*]
set ylabel "speedup"
set key top left font ",8"
plot $(plotlist 4), x with lines lc rgb "gray" dt 3 title "linear", $NPROC with lines lc rgb "black" dt 3 title "cores"
GP

traces=$(ls "$OUT"/traces/rad-*.tsv 2>/dev/null || true)
if [ -n "$traces" ]; then
  list=""
  for f in $traces; do
    name=$(basename "$f" .tsv)
    name=${name#rad-}
    list="$list${list:+, }\"$f\" using 1:3 with lines lw 2 title \"${name//-/ }\""
  done
  gnuplot <<GP
set terminal pngcairo size 800,520 noenhanced
set output "$OUT/unshot.png"
set logscale y
set grid
set xlabel "seconds (compute phase)"
set ylabel "max unshot power / emitted"
set title "vwalls radiosity, room: convergence per layout ($NPROC cores)"
plot $list
GP
fi
