#!/usr/bin/env bash
# peers.sh - the peers and limits of bench/experiments.sh, measured in the same run on
# the same scenes: POV-Ray 3.7 on the 1000-sphere scenes (whole process, 1 and 2 threads,
# against vwalls on 1 cell); Embree's raw ray-casting loop over the same ray tree
# (vw_bench_embree_raw: the kernel limit, against vwalls' compute phase on 1 cell); peak
# RSS per process under mpirun with P processes against one process, on a scene big
# enough for the scene to matter; and the per-cell load overlays before and after
# balancing. Writes peers.csv, memory.csv and peers.md into OUT. Skips what is missing.
#   usage: peers.sh OUT VWALLS EMBREE_RAW SIZE REPEAT HAVE_MPI HAVE_BALANCE
set -uo pipefail
OUT=$1 VW=$2 RAW=$3 SIZE=$4 REPEAT=$5 HAVE_MPI=$6 HAVE_BALANCE=$7
HERE=$(cd "$(dirname "$0")" && pwd)
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
MPIRUN=$(command -v mpirun || command -v mpiexec || true)
MPIFLAGS=()
[ -n "$MPIRUN" ] && "$MPIRUN" --version 2>/dev/null | grep -q "Open MPI" && MPIFLAGS=(--oversubscribe)
MEMCOUNT=${MEMCOUNT:-200000}
BALANCE=${BALANCE:-tensor}

# best N CMD...: smallest whole-process wall time of N runs, seconds
best() {
  local n=$1 b="" s e d; shift
  for _ in $(seq "$n"); do
    s=$(date +%s.%N)
    "$@" >/dev/null 2>"$T/err" || { cat "$T/err" >&2; echo 0; return 1; }
    e=$(date +%s.%N)
    d=$(awk -v a="$s" -v b="$e" 'BEGIN { printf "%.3f", b - a }')
    if [ -z "$b" ] || awk -v d="$d" -v b="$b" 'BEGIN { exit !(d < b) }'; then b=$d; fi
  done
  echo "$b"
}
field() { awk -f "$HERE/stats.awk" "$1" | sed -n "s/^$2=//p"; }

echo "kind,scene,threads,vwalls_s,peer_s,peer_over_vwalls,vwalls_mrays_s,peer_mrays_s" > "$OUT/peers.csv"
for s in s1000-c0 s1000-c0.5 s1000-c1; do
  nff=$OUT/scenes/$s.nff
  [ -f "$nff" ] || continue
  # POV-Ray: whole process (parse, build, render, write) against whole vwalls process
  if command -v povray >/dev/null && command -v python3 >/dev/null; then
    python3 "$HERE/../nff2pov.py" "$nff" "$SIZE" "$SIZE" 5 > "$T/$s.pov"
    for th in 1 2; do
      vw=$(best "$REPEAT" "$VW" render "$nff" -o "$T/vw.png" --size "${SIZE}x${SIZE}" --depth 5 --cells 1 --workers "$th" --quiet)
      pov=$(cd "$T" && best "$REPEAT" povray +I"$T/$s.pov" +O"$T/pov.png" +W"$SIZE" +H"$SIZE" -D -A +Q9 File_Gamma=1.0 +WT"$th")
      echo "povray,$s,$th,$vw,$pov,$(awk -v a="$pov" -v b="$vw" 'BEGIN { printf "%.2f", (b > 0 ? a / b : 0) }'),," >> "$OUT/peers.csv"
    done
  else
    echo "peers: no povray or python3: POV-Ray comparison skipped" >&2
  fi
  # Embree raw: the trace loop alone against vwalls' compute phase, 1 thread, 1 cell
  j=$OUT/json/raytrace-$s-1x1-threads-p1-w1-none.json
  if [ -x "$RAW" ] && [ -f "$j" ]; then
    raw=$("$RAW" "$nff" "${SIZE}x${SIZE}" 5)
    rt=$(echo "$raw" | sed -n 's/.*trace \([0-9.]*\) s.*/\1/p')
    rr=$(echo "$raw" | sed -n 's/.*rays \([0-9]*\),.*/\1/p')
    vc=$(field "$j" compute) vr=$(field "$j" rays)
    echo "embree_raw,$s,1,$vc,$rt,$(awk -v a="$rt" -v b="$vc" 'BEGIN { printf "%.2f", (b > 0 ? a / b : 0) }'),$(awk -v n="$vr" -v t="$vc" 'BEGIN { printf "%.3f", n / t / 1e6 }'),$(awk -v n="$rr" -v t="$rt" 'BEGIN { printf "%.3f", n / t / 1e6 }')" >> "$OUT/peers.csv"
  fi
done

# Memory: peak RSS of each process, a big uniform scene, a small image (the image buffer
# must not hide the scene). One process with 1 and 8 workers, then 2, 4, 8 processes.
echo "engine,processes,workers,layout,objects,rss_max_mb,rss_min_mb,rss_sum_mb,max_over_one" > "$OUT/memory.csv"
big=$T/big.nff
"$VW" gen spheres --count "$MEMCOUNT" --seed 1 -o "$big"
one=""
mem() { # mem ENGINE P W LAYOUT
  local j=$T/mem.json
  rm -f "$j"
  if [ "$1" = mpi ]; then
    "$MPIRUN" -np "$2" "${MPIFLAGS[@]}" "$VW" render "$big" -o "$T/big.png" --size 128x128 --cells "$4" --workers "$3" --farm none --quiet --stats "$j" >/dev/null 2>&1
  else
    "$VW" render "$big" -o "$T/big.png" --size 128x128 --cells "$4" --workers "$3" --farm none --quiet --stats "$j" >/dev/null 2>&1
  fi
  [ -s "$j" ] || { echo "peers: memory run $* failed" >&2; return; }
  local mx mn sm
  mx=$(field "$j" rss_max_mb) mn=$(field "$j" rss_min_mb) sm=$(field "$j" rss_sum_mb)
  [ -z "$one" ] && one=$mx
  echo "$1,$2,$3,$4,$MEMCOUNT,$mx,$mn,$sm,$(awk -v a="$mx" -v b="$one" 'BEGIN { printf "%.2f", a / b }')" >> "$OUT/memory.csv"
}
mem threads 1 1 1
mem threads 1 8 2x4
if [ "$HAVE_MPI" = 1 ]; then
  mem mpi 2 1 1x2
  mem mpi 4 1 2x2
  mem mpi 8 1 2x4
fi

# Load maps: each cell's pixels tinted by its measured load, the hardest scene on 2x4
rm -f "$OUT"/overlay-*.png
# (the walls divide the sphere scenes' space, as in the table: experiments.sh, WORLD; the
# balancer counts segments, as the table's rows of more workers than cores do)
hard=$OUT/scenes/s1000-c1.nff
if [ -f "$hard" ]; then
  "$VW" render "$hard" -o "$T/o.png" --size "${SIZE}x${SIZE}" --cells 2x4 --workers 8 --farm none --quiet \
    --world 0,0,0,10,10,10 --overlay "$OUT/overlay-none.png" --stats "$T/o.json" >/dev/null 2>&1
  if [ "$HAVE_BALANCE" = 1 ]; then
    for b in $BALANCE; do
      "$VW" render "$hard" -o "$T/o.png" --size "${SIZE}x${SIZE}" --cells 2x4 --workers 8 --quiet \
        --world 0,0,0,10,10,10 --balance-load segments --balance "$b" --overlay "$OUT/overlay-$b.png" >/dev/null 2>&1 || echo "peers: overlay $b failed" >&2
    done
  fi
fi

# peers.md
{
  echo "| peer | scene | threads | vwalls s | peer s | peer / vwalls | vwalls Mrays/s | peer Mrays/s |"
  echo "|---|---|--:|--:|--:|--:|--:|--:|"
  awk -F, 'NR > 1 { printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", ($1 == "povray" ? "POV-Ray 3.7 (whole process)" : "Embree raw loop (trace only)"), $2, $3, $4, $5, $6, $7, $8 }' "$OUT/peers.csv"
  echo
  echo "| engine | processes × workers | layout | spheres | peak RSS MB, max | min | sum | max / one process |"
  echo "|---|--:|---|--:|--:|--:|--:|--:|"
  awk -F, 'NR > 1 { printf "| %s | %s × %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6, $7, $8, $9 }' "$OUT/memory.csv"
} > "$OUT/peers.md"
