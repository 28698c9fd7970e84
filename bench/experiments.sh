#!/usr/bin/env bash
# experiments.sh - the paper's evaluation (Menzel et al. 1994), reproduced and extended,
# in one run: ray tracing of 100/500/1000 spheres (uniform, 50% and 100% clustered) and
# radiosity of a ~3600-patch room on cell layouts 1x1, 1x2, 2x2, 2x3, 2x4 (one cell per
# processor), on the threads engine and (a subset) under mpirun, with and without load
# balancing when `vwalls render --balance` exists; then the peers and limits (POV-Ray
# 3.7, Embree's raw ray-casting loop, per-process memory under MPI) and the plots.
#
# speedup = fastest sequential time / this row's time, both the compute phase plus the
# balancing phase if any; sequential = 1 worker (1 cell, or the walls on one worker when
# that is faster: the paper divides by the fastest sequential run);
# efficiency = speedup / workers (all processes). On a machine with fewer cores than
# workers these fall with the core count, not with the method, so every row also carries
# what does not depend on the core count: lambda (max/mean of the workers' busy time,
# from the stats JSON), 1/lambda, the total busy time, messages and bytes.
#
# usage: bench/experiments.sh [--smoke] [--out DIR] [--build DIR] [--publish]
#   --smoke    tiny scenes, two layouts, no peers or plots (ctest: tests/experiments.cmake)
#   --out      where the CSV, Markdown, JSON and plots go (default out/experiments of
#              this repository, wherever it is run from)
#   --build    the build directory holding vwalls (default $VW_BUILD_DIR, else build/ of
#              this repository)
#   --publish  also copy the plots to docs/bench/ and rewrite BENCHMARKS.md
# Environment: REPEAT (render runs per row, best kept), SIZE (image side), RSF (radiosity
# stopping ratio), BALANCE (strategies for the balanced rows, default "tensor"),
# BALANCE_LOAD (the balancer's load, `--balance-load`: busy or segments; default: busy
# where a row has no more workers than cores, segments where it has more).
#
# Why segments on an oversubscribed row: the balancer's pre-pass lasts milliseconds, and
# a worker's busy time on 8 workers sharing 2 cores is mostly the time it waited for a
# core. Balancing on it moved walls by the scheduler's noise: 1000 spheres 100% clustered,
# 2x4, tensor, work lambda 1.20 to 2.24 over five runs (none: 1.51), where the counted
# segments give 1.15 every run. The table's deterministic columns are counted segments,
# so the balancer is given the same figure.
# Needs bash, awk; optional: mpirun, gnuplot, povray + python3 (nff2pov.py).
set -uo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/.." && pwd)
EXP=$HERE/experiments

SMOKE=0 PUBLISH=0
OUT=$ROOT/out/experiments
BUILD=${VW_BUILD_DIR:-$ROOT/build}
while [ $# -gt 0 ]; do
  case "$1" in
    --smoke) SMOKE=1 ;;
    --publish) PUBLISH=1 ;;
    --out) OUT=$2; shift ;;
    --build) BUILD=$2; shift ;;
    -h|--help) sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "experiments.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
  shift
done
VW=$BUILD/vwalls
RAW=$BUILD/vw_bench_embree_raw
[ -x "$VW" ] || { echo "experiments.sh: no $VW (build first: ./run build)" >&2; exit 1; }

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
NPROC=$(nproc 2>/dev/null || echo 1)
mkdir -p "$OUT/json" "$OUT/scenes" "$OUT/traces"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
LOG=$OUT/run.log
: > "$LOG"
RAWTSV=$OUT/raw.tsv
: > "$RAWTSV"
FAILED=0
START=$(date +%s)
LOAD_START=$(cut -d" " -f1-3 /proc/loadavg 2>/dev/null)

if [ $SMOKE = 1 ]; then
  COUNTS=${COUNTS:-300}; CLUSTERS=${CLUSTERS:-"0 0.5"}; SIZE=${SIZE:-256}
  LAYOUTS="1x1 1x2"; MPI_LAYOUTS="1x2"; MPI_SCENES="s300-c0.5"
  REPEAT=${REPEAT:-3}; MREPEAT=1; RREPEAT=2
  RSCENE=cornell; RSF=${RSF:-3e-3}; RPATCH=""; RSEQ_LAYOUTS="1x2"
else
  COUNTS=${COUNTS:-"100 500 1000"}; CLUSTERS=${CLUSTERS:-"0 0.5 1"}; SIZE=${SIZE:-512}
  LAYOUTS="1x1 1x2 2x2 2x3 2x4"; MPI_LAYOUTS="1x2 2x2 2x4"; MPI_SCENES="s1000-c0 s1000-c1"
  REPEAT=${REPEAT:-3}; MREPEAT=2; RREPEAT=1
  RSCENE=room; RSF=${RSF:-2.5e-4}; RPATCH="--patch-size 0.21"; RSEQ_LAYOUTS="1x2 2x4"
fi
BALANCE=${BALANCE:-tensor}
BALANCE_LOAD=${BALANCE_LOAD:-}
# bload WORKERS: the --balance-load a balanced row of WORKERS workers (threads) gets
bload() { if [ -n "$BALANCE_LOAD" ]; then echo "$BALANCE_LOAD"; elif [ "$1" -gt "$NPROC" ]; then echo segments; else echo busy; fi; }

note() { echo "$*" | tee -a "$LOG" >&2; }
cells_of() { awk -v l="$1" 'BEGIN { n = split(l, a, "x"); c = 1; for (i = 1; i <= n; i++) c *= a[i]; print c }'; }

# What this build and machine can do; rows that need a missing feature are left out
# and the reason is written to the log and the Markdown.
HAVE_BALANCE=0
"$VW" render --help 2>&1 | grep -q -- '--balance' && HAVE_BALANCE=1
HAVE_RBALANCE=0
"$VW" radiosity --help 2>&1 | grep -q -- '--balance' && HAVE_RBALANCE=1
MPIRUN=$(command -v mpirun || command -v mpiexec || true)
MPIFLAGS=()
HAVE_MPI=0
if [ -n "$MPIRUN" ]; then
  "$MPIRUN" --version 2>/dev/null | grep -q "Open MPI" && MPIFLAGS=(--oversubscribe)
  "$VW" gen spheres --count 10 --seed 1 -o "$T/probe.nff" 2>>"$LOG"
  if timeout 60 "$MPIRUN" -np 2 "${MPIFLAGS[@]}" "$VW" render "$T/probe.nff" -o "$T/probe.png" \
       --size 16x16 --cells 1x2 --workers 1 --quiet --stats "$T/probe.json" >>"$LOG" 2>&1 &&
     [ "$(awk -f "$EXP/stats.awk" "$T/probe.json" | sed -n 's/^processes=//p')" = 2 ]; then
    HAVE_MPI=1
  fi
fi
note "experiments: $( [ $SMOKE = 1 ] && echo smoke || echo full ) run, $NPROC cores, size ${SIZE}x${SIZE}," \
     "balance $( [ $HAVE_BALANCE = 1 ] && echo "yes ($BALANCE)" || echo "not in this build" )," \
     "MPI $( [ $HAVE_MPI = 1 ] && echo yes || echo no )"

# row APP SCENE LAYOUT ENGINE PROCS WORKERS BALANCE REPEAT -- COMMAND...
# Runs COMMAND (which must write its stats to $J) REPEAT times and appends one line to
# raw.tsv: the run with the smallest compute phase gives every figure but the whole-process
# wall time, which is the smallest of all runs (noise on a shared machine only adds time).
# CPU is the user+sys of the whole process tree of the kept run (bash's `time`).
row() {
  local app=$1 scene=$2 layout=$3 engine=$4 procs=$5 workers=$6 bal=$7 rep=$8; shift 9
  local tag="$app-$scene-$layout-$engine-p$procs-w$workers-$bal"
  local best="" bestwall="" bestcpu="" i rc tm
  for i in $(seq "$rep"); do
    J=$OUT/json/$tag.r$i.json
    export J
    rm -f "$J"
    TIMEFORMAT='%R %U %S'
    { time "$@" >>"$LOG" 2>&1; } 2>"$T/time" && rc=0 || rc=$?
    tm=$(tail -1 "$T/time")
    if [ $rc != 0 ] || [ ! -s "$J" ]; then
      note "FAILED ($rc): $tag: $*"
      FAILED=$((FAILED + 1))
      return 1
    fi
    local c
    c=$(awk -f "$EXP/stats.awk" "$J" | sed -n 's/^compute=//p')
    local wall cpu
    wall=${tm%% *}
    cpu=$(echo "$tm" | awk '{ printf "%.3f", $2 + $3 }')
    if [ -z "$bestwall" ] || awk -v a="$wall" -v b="$bestwall" 'BEGIN { exit !(a < b) }'; then bestwall=$wall; fi
    if [ -z "$best" ] || awk -v a="$c" -v b="$best" 'BEGIN { exit !(a < b) }'; then
      best=$c; bestcpu=$cpu
      cp "$J" "$OUT/json/$tag.json"
    fi
  done
  rm -f "$OUT"/json/"$tag".r*.json
  awk -f "$EXP/stats.awk" "$OUT/json/$tag.json" | sort > "$T/kv"
  printf 'app=%s\nscene=%s\nlayout=%s\nengine=%s\nbal=%s\nrepeat=%s\nwall=%s\ncpu=%s\ntag=%s\n' \
    "$app" "$scene" "$layout" "$engine" "$bal" "$rep" "$bestwall" "$bestcpu" "$tag" >> "$T/kv"
  # one line of key=value pairs; report.awk reads it
  tr '\n' '\t' < "$T/kv" >> "$RAWTSV"
  echo >> "$RAWTSV"
  printf '  %-9s %-9s %-4s %-7s P%-2s W%-2s %-9s compute %s s, whole %s s\n' "$app" "$scene" "$layout" \
    "$engine" "$procs" "$workers" "$bal" "$best" "$bestwall" >&2
}

launch() { # launch ENGINE PROCS COMMAND...: the command itself or under mpirun
  local engine=$1 procs=$2; shift 2
  if [ "$engine" = mpi ]; then "$MPIRUN" -np "$procs" "${MPIFLAGS[@]}" "$@"; else "$@"; fi
}
# The paper's setting: cells mapped onto the workers, rays crossing between workers as
# messages (--farm none; the default would farm the cells among a process's workers).
# The sphere scenes' space: `vwalls gen spheres` places them in the cube [0,10]^3, its
# cluster region in one octant of it. The walls divide that cube, as the paper's grids
# divided the scene space: without --world the world box is the objects' bounds, which at
# 100% clustering is the cluster's own box, evenly cut, and the clustered load case the
# paper made to unbalance the cells would be no harder than the uniform one.
WORLD=0,0,0,10,10,10
render() { # render ENGINE PROCS SCENE LAYOUT WORKERS [options...]
  local engine=$1 procs=$2 scene=$3 layout=$4 workers=$5; shift 5
  launch "$engine" "$procs" "$VW" render "$OUT/scenes/$scene.nff" -o "$T/$scene.png" \
    --size "${SIZE}x${SIZE}" --depth 5 --cells "$layout" --workers "$workers" --farm none \
    --world "$WORLD" --quiet --stats "$J" "$@"
}
radiosity() { # radiosity ENGINE PROCS LAYOUT WORKERS [options...]
  local engine=$1 procs=$2 layout=$3 workers=$4; shift 4
  # shellcheck disable=SC2086
  launch "$engine" "$procs" "$VW" radiosity "$OUT/scenes/$RSCENE.nff" -o "$T/rad.ply" $RPATCH \
    --sf "$RSF" --cells "$layout" --workers "$workers" --quiet --stats "$J" "$@"
}

# ---- ray tracing: the paper's sphere scenes -----------------------------------------
SCENES=()
for n in $COUNTS; do
  for c in $CLUSTERS; do
    s=s$n-c$c
    "$VW" gen spheres --count "$n" --cluster "$c" --seed 1 --resolution "${SIZE}x${SIZE}" \
      -o "$OUT/scenes/$s.nff" 2>>"$LOG" || { note "FAILED: gen $s"; FAILED=$((FAILED + 1)); continue; }
    SCENES+=("$s")
  done
done
note "ray tracing: ${#SCENES[@]} scenes x layouts $LAYOUTS"
for s in "${SCENES[@]}"; do
  for l in $LAYOUTS; do
    n=$(cells_of "$l")
    row raytrace "$s" "$l" threads 1 "$n" none "$REPEAT" -- render threads 1 "$s" "$l" "$n"
    if [ $HAVE_BALANCE = 1 ] && [ "$n" -gt 1 ]; then
      for b in $BALANCE; do
        row raytrace "$s" "$l" threads 1 "$n" "$b" "$REPEAT" -- render threads 1 "$s" "$l" "$n" --balance "$b" \
          --balance-load "$(bload "$n")"
      done
    fi
  done
  # the same 8 cells on the cores this machine has: a true speedup, whatever the core count
  last=${LAYOUTS##* }
  if [ "$(cells_of "$last")" -gt "$NPROC" ] && [ "$NPROC" -gt 1 ]; then
    row raytrace "$s" "$last" threads 1 "$NPROC" none "$REPEAT" -- render threads 1 "$s" "$last" "$NPROC"
    # and farmed, as `vwalls render` runs by default: every worker holds every cell
    row raytrace "$s" "$last" threads 1 "$NPROC" farm "$REPEAT" -- render threads 1 "$s" "$last" "$NPROC" --farm all
  fi
  # and on one worker: a sequential candidate too (the paper divides by the fastest one)
  row raytrace "$s" "$last" threads 1 1 none "$REPEAT" -- render threads 1 "$s" "$last" 1
  if [ $HAVE_MPI = 1 ] && [[ " $MPI_SCENES " == *" $s "* ]]; then
    for l in $MPI_LAYOUTS; do
      n=$(cells_of "$l")
      row raytrace "$s" "$l" mpi "$n" 1 none "$MREPEAT" -- render mpi "$n" "$s" "$l" 1
    done
  fi
done
# every balancing strategy on the hardest case (all spheres in one corner, most cells)
if [ $HAVE_BALANCE = 1 ] && [ ${#SCENES[@]} -gt 0 ]; then
  hard=${SCENES[${#SCENES[@]}-1]} last=${LAYOUTS##* }
  n=$(cells_of "$last")
  # the strategies `vwalls render --help` lists (docs/balancing.md names five; a build may have fewer)
  strats=$("$VW" render --help 2>&1 | sed -n 's/.*--balance S *\([a-z|]*\).*/\1/p' | tr '|' ' ')
  for b in ${strats:-tensor rotate staggered divide duplicate}; do
    [ "$b" = none ] || [[ " $BALANCE " == *" $b "* ]] && continue
    row raytrace "$hard" "$last" threads 1 "$n" "$b" "$REPEAT" -- render threads 1 "$hard" "$last" "$n" --balance "$b" \
      --balance-load "$(bload "$n")"
  done
fi

# ---- radiosity ----------------------------------------------------------------------
"$VW" gen "$RSCENE" -o "$OUT/scenes/$RSCENE.nff" 2>>"$LOG" || { note "FAILED: gen $RSCENE"; FAILED=$((FAILED + 1)); }
note "radiosity: $RSCENE, sf $RSF, layouts $LAYOUTS"
for l in $LAYOUTS; do
  n=$(cells_of "$l")
  rep=$RREPEAT; [ "$n" = 1 ] && rep=$((RREPEAT + 1))
  row radiosity "$RSCENE" "$l" threads 1 "$n" none "$rep" -- \
    radiosity threads 1 "$l" "$n" --trace "$OUT/traces/rad-$l-threads.tsv"
  if [ $HAVE_RBALANCE = 1 ] && [ "$n" -gt 1 ]; then
    for b in $BALANCE; do
      row radiosity "$RSCENE" "$l" threads 1 "$n" "$b" "$RREPEAT" -- \
        radiosity threads 1 "$l" "$n" --balance "$b" --trace "$OUT/traces/rad-$l-threads-$b.tsv"
    done
  fi
done
# sequential candidates with walls: fewer pieces per cell can make a shot cheaper, so the
# fastest sequential run need not be the one without walls
for l in $RSEQ_LAYOUTS; do
  row radiosity "$RSCENE" "$l" threads 1 1 none "$RREPEAT" -- radiosity threads 1 "$l" 1
done
# (not in the smoke run, which has its MPI row already; on the Cornell box's few shots the
# MPI engine's compute phase is a fraction of the threads engine's for the same shots,
# an efficiency above 1 that says nothing about the method)
if [ $HAVE_MPI = 1 ] && [ $SMOKE = 0 ]; then
  for l in $MPI_LAYOUTS; do
    n=$(cells_of "$l")
    row radiosity "$RSCENE" "$l" mpi "$n" 1 none 1 -- radiosity mpi "$n" "$l" 1 --trace "$OUT/traces/rad-$l-mpi.tsv"
  done
fi

# ---- the table ----------------------------------------------------------------------
awk -v nproc="$NPROC" -f "$EXP/report.awk" "$RAWTSV" > "$OUT/results.csv"
awk -F, -f "$EXP/check.awk" "$OUT/results.csv" | tee -a "$LOG" >&2 || FAILED=$((FAILED + 1))
awk -F, -f "$EXP/table.awk" "$OUT/results.csv" > "$OUT/results.md"

if [ $SMOKE = 0 ]; then
  # ---- peers and limits -------------------------------------------------------------
  bash "$EXP/peers.sh" "$OUT" "$VW" "$RAW" "$SIZE" "$REPEAT" "$HAVE_MPI" "$HAVE_BALANCE" 2>>"$LOG" ||
    note "peers.sh failed (see $LOG)"
  # ---- plots ------------------------------------------------------------------------
  if command -v gnuplot >/dev/null; then
    bash "$EXP/plots.sh" "$OUT" 2>>"$LOG" || note "plots.sh failed (see $LOG)"
  else
    note "no gnuplot: no plots"
  fi
fi

ELAPSED=$(( $(date +%s) - START ))
{
  echo "seconds=$ELAPSED"; echo "nproc=$NPROC"; echo "size=$SIZE"; echo "repeat=$REPEAT"
  echo "rsf=$RSF"; echo "have_balance=$HAVE_BALANCE"; echo "have_rbalance=$HAVE_RBALANCE"
  echo "load_start=$LOAD_START"; echo "load_end=$(cut -d" " -f1-3 /proc/loadavg 2>/dev/null)"
  echo "have_mpi=$HAVE_MPI"; echo "balance=$BALANCE"; echo "balance_load=${BALANCE_LOAD:-auto}"; echo "failed=$FAILED"
  echo "date=$(date -u +%Y-%m-%dT%H:%MZ)"; echo "commit=$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null)"
} > "$OUT/run.env"
if [ $PUBLISH = 1 ]; then
  bash "$EXP/publish.sh" "$OUT" "$ROOT" || note "publish.sh failed"
fi
note "experiments: $ELAPSED s; $OUT/results.csv, $OUT/results.md$( [ $FAILED = 0 ] || echo "; $FAILED FAILURES (see $LOG)")"
[ $FAILED = 0 ]
