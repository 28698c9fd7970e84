#!/bin/bash
# raytrace.sh - the ray tracer's benchmarks, measured side by side in one run:
#  (a) vwalls render vs POV-Ray 3.7 on the same sphereflake (SIZE, 1 sample/pixel,
#      depth 5, its 3 lights), one thread each and two threads each;
#  (b) vwalls on 1 cell vs a raw rtcIntersect1/rtcOccluded1 loop over the same ray tree
#      (bench/embree_raw.c): the framework's overhead over Embree's kernel;
#  (c) 2x2x2 cells vs 1 cell on 1 worker, and 2 workers vs 1: whole processes, then
#      the compute phase alone (from the stats) and the two workers' busy time. Two
#      workers run the cells mapped onto them (--farm none: rays cross between workers
#      as messages) and farmed (--farm all: each worker holds a copy of every cell);
#      1 cell on 2 workers is farmed by default (--farm auto: all);
#      The compute-phase ratios are also given within each round (median and range):
#      a round runs every configuration back to back, at the machine's speed of the moment;
#      the whole processes of those rounds likewise, and the phases of the one-cell runs
#      (what does not shrink with a second worker bounds the whole-process speedup);
#  (d) 2x2x2 against 1 cell by instruction count (callgrind): free of the noise;
#  (e) 2x2x2 against 1 cell on the next sphereflake (size 5), in time and instructions.
# Whole processes are timed with date +%s.%N: best of REPEAT runs, the configurations
# interleaved (one run of each per round: the shared machine's speed drifts).
# usage: bench/raytrace.sh [BUILD_DIR] [SIZE] [REPEAT]     (e.g. bench/raytrace.sh build 512 3)
# Needs povray and python3 (scripts/setup.sh bench); valgrind for (d), skipped without.
set -euo pipefail
B=${1:-${VW_BUILD_DIR:-build}}
SIZE=${2:-512}
REPEAT=${3:-3}
HERE=$(cd "$(dirname "$0")" && pwd)
VW=$B/vwalls
RAW=$B/vw_bench_embree_raw
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT

for x in "$VW" "$RAW"; do
  [ -x "$x" ] || { echo "raytrace.sh: $x not built (cmake --build $B)" >&2; exit 1; }
done
for x in povray python3; do
  command -v "$x" > /dev/null ||
    { echo "raytrace.sh: $x is needed (scripts/setup.sh bench installs it)" >&2; exit 1; }
done

# The scene: SPD "balls" (sphereflake, level 4: 7381 spheres on a floor polygon, 3 lights).
if "$VW" gen balls > "$T/balls.nff" 2>/dev/null; then :; else
  "$B/vw_test_raytrace" nff gen:balls:4 > "$T/balls.nff"
fi
python3 "$HERE/nff2pov.py" "$T/balls.nff" "$SIZE" "$SIZE" 5 > "$T/balls.pov"

# Wall time of one whole command, in seconds.
once() {
  local s e
  s=$(date +%s.%N)
  "$@" > "$T/last.out" 2> "$T/last.err" || { cat "$T/last.err" >&2; exit 1; }
  e=$(date +%s.%N)
  awk -v a="$s" -v b="$e" 'BEGIN { printf "%.3f", b - a }'
}
# Best-of-REPEAT wall times of named commands, run interleaved (every command once per
# round), so that a drift of the shared machine's speed hits them all alike:
#   timeall NAME 'command args' NAME 'command args' ...   ->  BEST[NAME]
declare -A BEST
timeall() {
  local -a names=() cmds=()
  while [ $# -gt 0 ]; do names+=("$1"); cmds+=("$2"); shift 2; done
  for _ in $(seq "$REPEAT"); do
    for k in "${!names[@]}"; do
      local t
      t=$(once ${cmds[$k]})
      local n=${names[$k]}
      if [ -z "${BEST[$n]:-}" ] || awk -v a="$t" -v b="${BEST[$n]}" 'BEGIN { exit !(a < b) }'; then
        BEST[$n]=$t
      fi
    done
  done
}
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", a / b }'; }

render() { "$VW" render "$T/balls.nff" -o "$T/vw.png" --size "${SIZE}x${SIZE}" --depth 5 --quiet "$@"; }
pov() {
  (cd "$T" && povray +I"$T/balls.pov" +O"$T/pov.png" +W"$SIZE" +H"$SIZE" -D -A +Q9 \
     File_Gamma=1.0 +WT"$1")
}

echo "ray tracer benchmark: sphereflake (balls), ${SIZE}x${SIZE}, depth 5, best of $REPEAT"
echo "machine: $(nproc) cores; $(uname -sr)"
echo

# (a) and (c): every whole-process configuration, interleaved
timeall vw1 'render --cells 1 --workers 1' pov1 'pov 1' \
        vw2 'render --cells 1 --workers 2' vw2c 'render --cells 2x2x2 --workers 2 --farm none' \
        vw2f 'render --cells 2x2x2 --workers 2 --farm all' pov2 'pov 2' \
        c8 'render --cells 2x2x2 --workers 1'
vw1=${BEST[vw1]} pov1=${BEST[pov1]} vw2=${BEST[vw2]} vw2c=${BEST[vw2c]} vw2f=${BEST[vw2f]}
pov2=${BEST[pov2]} c8=${BEST[c8]}
echo "(a) vs POV-Ray 3.7 (whole process: parse + build + render + write)"
printf "    1 thread : vwalls %6.3f s   povray %6.3f s   povray/vwalls = %s\n" "$vw1" "$pov1" "$(ratio "$pov1" "$vw1")"
printf "    2 threads: vwalls %6.3f s   povray %6.3f s   povray/vwalls = %s  (vwalls 1 cell)\n" "$vw2" "$pov2" "$(ratio "$pov2" "$vw2")"
printf "               vwalls %6.3f s (2x2x2, farm none)     povray/vwalls = %s\n" "$vw2c" "$(ratio "$pov2" "$vw2c")"
printf "               vwalls %6.3f s (2x2x2, farm all: the default) povray/vwalls = %s\n" "$vw2f" "$(ratio "$pov2" "$vw2f")"
echo

# (b) vs raw Embree: rays/s of vwalls' own compute phase and of the raw loop, best of
# REPEAT each, interleaved
vw_best="" raw_best=""
for i in $(seq "$REPEAT"); do
  render --cells 1 --workers 1 --stats "$T/s1.json"
  vw_rays=$(python3 -c "import json,sys; j=json.load(open('$T/s1.json')); r=j['rays']; print(r['eye']+r['reflect']+r['refract']+r['shadow'], j['time_s']['compute'])")
  raw_out=$("$RAW" "$T/balls.nff" "${SIZE}x${SIZE}" 5)
  raw_rays=$(echo "$raw_out" | sed -n 's/.*rays \([0-9]*\),.*/\1/p')
  raw_time=$(echo "$raw_out" | sed -n 's/.*trace \([0-9.]*\) s.*/\1/p')
  set -- $vw_rays
  if [ -z "$vw_best" ] || awk -v a="$2" -v b="$vw_best" 'BEGIN { exit !(a < b) }'; then vw_best=$2; fi
  if [ -z "$raw_best" ] || awk -v a="$raw_time" -v b="$raw_best" 'BEGIN { exit !(a < b) }'; then raw_best=$raw_time; fi
done
set -- "$1" "$vw_best"
raw_time=$raw_best
vw_rate=$(awk -v n="$1" -v t="$2" 'BEGIN { printf "%.3f", n / t * 1e-6 }')
raw_rate=$(awk -v n="$raw_rays" -v t="$raw_time" 'BEGIN { printf "%.3f", n / t * 1e-6 }')
echo "(b) vs raw Embree, 1 thread (compute phase only)"
printf "    vwalls 1 cell: %s rays in %s s = %s Mrays/s\n" "$1" "$2" "$vw_rate"
printf "    embree raw   : %s rays in %s s = %s Mrays/s\n" "$raw_rays" "$raw_time" "$raw_rate"
printf "    vwalls/raw rate = %s\n" "$(ratio "$vw_rate" "$raw_rate")"
echo

# (c) cells and workers
c1=$vw1
w2=$vw2
echo "(c) cells and workers (whole process)"
printf "    1 worker : 1 cell %6.3f s, 2x2x2 %6.3f s   2x2x2/1cell time = %s\n" "$c1" "$c8" "$(ratio "$c8" "$c1")"
printf "    1 cell   : 1 worker %6.3f s, 2 workers %6.3f s   speedup = %s\n" "$c1" "$w2" "$(ratio "$c1" "$w2")"
printf "    2x2x2    : 1 worker %6.3f s, 2 workers %6.3f s   speedup = %s  (farm none)\n" "$c8" "$vw2c" "$(ratio "$c8" "$vw2c")"
printf "    2x2x2    : 1 worker %6.3f s, 2 workers %6.3f s   speedup = %s  (farm all)\n" "$c8" "$vw2f" "$(ratio "$c8" "$vw2f")"
# The compute phase alone (no parse, build or PNG): best of REPEAT runs each, from
# the stats; and where the time of 2x2x2 on 2 workers goes.
# Interleaved, so that a drift of the machine's speed hits every configuration alike.
for i in $(seq "$REPEAT"); do
  for cfg in "1 1 auto" "1 2 auto" "2x2x2 1 none" "2x2x2 2 none" "2x2x2 2 all"; do
    set -- $cfg
    once render --cells "$1" --workers "$2" --farm "$3" --stats "$T/c-$1-$2-$3-$i.json" \
      > "$T/c-$1-$2-$3-$i.wall"
  done
done
python3 - "$T" "$REPEAT" <<'EOF'
import json, sys
t, n = sys.argv[1], int(sys.argv[2])
def runs(c, w, f): return [json.load(open("%s/c-%s-%s-%s-%d.json" % (t, c, w, f, i))) for i in range(1, n + 1)]
def best(c, w, f): return min(j["time_s"]["compute"] for j in runs(c, w, f))
one, one2 = best("1", 1, "auto"), best("1", 2, "auto")
c8, c8w2, c8f = best("2x2x2", 1, "none"), best("2x2x2", 2, "none"), best("2x2x2", 2, "all")
print("    compute phase only (best of %d, interleaved):" % n)
print("      1 cell : 1 worker %.3f s, 2 workers %.3f s (speedup %.2f, farm auto)" % (one, one2, one / one2))
print("      2x2x2  : 1 worker %.3f s (x%.2f of 1 cell), 2 workers %.3f s (speedup %.2f, farm none),"
      " %.3f s (speedup %.2f, farm all)" % (c8, c8 / one, c8w2, c8 / c8w2, c8f, c8 / c8f))
# Each round ran the configurations back to back: a round's ratios share the machine's
# speed of the moment, so their median and range say more than a ratio of two bests
# (which may come from different rounds).
def wall(c, w, f): return [float(open("%s/c-%s-%s-%s-%d.wall" % (t, c, w, f, i)).read()) for i in range(1, n + 1)]
def median_range(r):
    r = sorted(r)
    m = r[len(r) // 2] if len(r) % 2 else (r[len(r) // 2 - 1] + r[len(r) // 2]) / 2
    return "median %.2f (%.2f-%.2f)" % (m, r[0], r[-1])
def paired(a, b):
    return median_range(x["time_s"]["compute"] / y["time_s"]["compute"] for x, y in zip(runs(*a), runs(*b)))
def paired_wall(a, b): return median_range(x / y for x, y in zip(wall(*a), wall(*b)))
print("    compute phase, ratios within each round (%d rounds):" % n)
print("      2x2x2/1 cell, 1 worker: %s" % paired(("2x2x2", 1, "none"), ("1", 1, "auto")))
print("      2 workers vs 1: 1 cell %s; 2x2x2 farm all %s, farm none %s" % (
    paired(("1", 1, "auto"), ("1", 2, "auto")), paired(("2x2x2", 1, "none"), ("2x2x2", 2, "all")),
    paired(("2x2x2", 1, "none"), ("2x2x2", 2, "none"))))
print("    whole process, ratios within each round (%d rounds):" % n)
print("      2x2x2/1 cell, 1 worker: %s" % paired_wall(("2x2x2", 1, "none"), ("1", 1, "auto")))
print("      2 workers vs 1: 1 cell %s; 2x2x2 farm all %s, farm none %s" % (
    paired_wall(("1", 1, "auto"), ("1", 2, "auto")), paired_wall(("2x2x2", 1, "none"), ("2x2x2", 2, "all")),
    paired_wall(("2x2x2", 1, "none"), ("2x2x2", 2, "none"))))
# Where the whole process goes besides the compute phase (medians over the rounds, ms):
# the phases that do not shrink with a second worker bound the whole-process speedup.
def phases(c, w, f):
    js, walls = runs(c, w, f), wall(c, w, f)
    med = lambda xs: sorted(xs)[len(xs) // 2]
    ph = ["load", "build", "compute", "write"]
    out = ", ".join("%s %.1f" % (p, 1e3 * med([j["time_s"][p] for j in js])) for p in ph)
    rest = med([wl - j["time_s"]["total"] for j, wl in zip(js, walls)])
    return "%s, outside them (start, exit) %.1f" % (out, 1e3 * rest)
print("    phases, 1 cell (medians, ms): 1 worker: %s" % phases("1", 1, "auto"))
print("                                 2 workers: %s" % phases("1", 2, "auto"))
b1 = sum(w["busy_s"] for w in runs("2x2x2", 1, "none")[-1]["workers"])
for f in ("none", "all"):
    j = runs("2x2x2", 2, f)[-1]
    b2 = sum(w["busy_s"] for w in j["workers"])
    print("    2x2x2 on 2 workers, farm %s: imbalance lambda %.3f, worker busy %s s (sum %.2fx one"
          " worker's), messages %d (%.1f MB)" % (f,
        j["balance"]["imbalance"], ", ".join("%.3f" % w["busy_s"] for w in j["workers"]), b2 / b1,
        j["messages"]["count"], j["messages"]["bytes"] / 1e6))
EOF

# (d) The decomposition overhead without the machine's noise: instructions executed by
# the whole process (valgrind's callgrind, one worker, 256x256: the ratio hardly depends
# on the size), 2x2x2 cells against 1 cell. Skipped when valgrind is not installed.
# Instructions of one render: instr SCENE CELLS (1 worker, 256x256, whole process).
instr() {
  valgrind --tool=callgrind --callgrind-out-file="$T/cg.out" "$VW" render "$1" \
    -o "$T/cg.png" --size 256x256 --depth 5 --quiet --workers 1 --cells "$2" 2>&1 |
    sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
if command -v valgrind > /dev/null 2>&1; then
  i1=$(instr "$T/balls.nff" 1)
  i8=$(instr "$T/balls.nff" 2x2x2)
  echo "(d) instructions (callgrind, 1 worker, 256x256, whole process)"
  printf "    1 cell %s, 2x2x2 %s: 2x2x2/1cell = %s\n" "$i1" "$i8" "$(awk -v a="$i8" -v b="$i1" 'BEGIN { printf "%.3f", a / b }')"
fi

# (e) The 2x2x2 overhead against the scene's size: a crossing costs the same whatever the
# scene, a segment's search in Embree grows with it, so the ratio of (c) falls on the
# next sphereflake (size 5: 66,430 spheres). Whole processes, interleaved, best of
# REPEAT; and by instruction count when valgrind is there.
if "$VW" gen balls --size 5 > "$T/balls5.nff" 2>/dev/null; then
  render5() { "$VW" render "$T/balls5.nff" -o "$T/vw5.png" --size "${SIZE}x${SIZE}" --depth 5 --quiet "$@"; }
  timeall b5c1 'render5 --cells 1 --workers 1' b5c8 'render5 --cells 2x2x2 --workers 1'
  echo "(e) the same on the size-5 sphereflake (66,430 spheres), 1 worker"
  printf "    whole process: 1 cell %6.3f s, 2x2x2 %6.3f s   2x2x2/1cell time = %s\n" \
    "${BEST[b5c1]}" "${BEST[b5c8]}" "$(ratio "${BEST[b5c8]}" "${BEST[b5c1]}")"
  if command -v valgrind > /dev/null 2>&1; then
    i1=$(instr "$T/balls5.nff" 1)
    i8=$(instr "$T/balls5.nff" 2x2x2)
    printf "    instructions (256x256): 1 cell %s, 2x2x2 %s: 2x2x2/1cell = %s\n" "$i1" "$i8" \
      "$(awk -v a="$i8" -v b="$i1" 'BEGIN { printf "%.3f", a / b }')"
  fi
fi
