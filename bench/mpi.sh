#!/bin/sh
# bench/mpi.sh - the MPI engine against the threads engine on the example module (a
# bigger problem): 1 process x 1 worker, 1 process x 2 workers, 2 processes x 1 worker,
# side by side, best of REPEAT runs each; prints compute time, ratios against 1x1, the
# busiest worker's time in the module (the rest of the compute phase is the runtime's:
# packets, waiting, and under MPI the termination waves; placing the objects, which
# every process does for the whole scene before keeping its own cells, and building
# the cells are phases of their own), the imbalance, and the messages and bytes that
# crossed processes.
# usage: bench/mpi.sh [BUILD_DIR] [SPHERES] [CELLS] [REPEAT]
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-${VW_BUILD_DIR:-$repo/build}}
n=${2:-400000}
cells=${3:-4x4x4}
repeat=${4:-3}
vwalls=$build/vwalls
[ -x "$vwalls" ] || { echo "bench/mpi.sh: no $vwalls (build first)" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
flags=""
mpiexec --version 2>/dev/null | grep -q "Open MPI" && flags="--oversubscribe"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
args="example-pairs --spheres $n --radius 0.004 --seed 7 --cells $cells --quiet"

field() { # field FILE SECTION KEY: a number from the stats JSON
    grep -o "\"$2\": {[^}]*}" "$1" | grep -o "\"$3\": [0-9.e+-]*" | head -1 | awk '{print $2}'
}
run() { # run NAME PROCS WORKERS
    best=""
    for i in $(seq "$repeat"); do
        if [ "$2" -eq 1 ]; then
            # shellcheck disable=SC2086
            "$vwalls" $args --workers "$3" --stats "$tmp/$1.json" >"$tmp/$1.out"
        else
            # shellcheck disable=SC2086
            mpiexec -n "$2" $flags "$vwalls" $args --workers "$3" --stats "$tmp/$1.json" >"$tmp/$1.out"
        fi
        t=$(field "$tmp/$1.json" time_s compute)
        if [ -z "$best" ] || awk "BEGIN{exit !($t < $best)}"; then
            best=$t
            cp "$tmp/$1.json" "$tmp/$1.best.json"
        fi
    done
    echo "$best" >"$tmp/$1.t"
}
run p1w1 1 1
run p1w2 1 2
run p2w1 2 1
t11=$(cat "$tmp/p1w1.t")
echo "example module: $n spheres, cells $cells, best of $repeat ($(nproc) cores)"
printf '%-22s %10s %8s %11s %9s %10s %12s %13s\n' engine compute_s vs_1x1 busy_max_s imbalance pairs remote_msgs remote_bytes
for c in p1w1:"1 process x 1 worker" p1w2:"1 process x 2 workers" p2w1:"2 processes x 1 worker"; do
    k=${c%%:*} name=${c#*:}
    t=$(cat "$tmp/$k.t")
    j=$tmp/$k.best.json
    busy=$(grep -o '"process": [0-9]*, "busy_s": [0-9.]*' "$j" | awk '{if ($4 > m) m = $4} END {print m}')
    printf '%-22s %10.3f %8.2f %11.4f %9.3f %10s %12s %13s\n' "$name" "$t" "$(awk "BEGIN{print $t11/$t}")" "$busy" \
        "$(field "$j" balance imbalance)" "$(cat "$tmp/$k.out")" \
        "$(field "$j" messages remote_count)" "$(field "$j" messages remote_bytes)"
done
t12=$(cat "$tmp/p1w2.t") t21=$(cat "$tmp/p2w1.t")
echo "speedup 1x2 threads: $(awk "BEGIN{printf \"%.2f\", $t11/$t12}"), 2x1 MPI: $(awk "BEGIN{printf \"%.2f\", $t11/$t21}"), MPI / threads time: $(awk "BEGIN{printf \"%.2f\", $t21/$t12}")"
cmp -s "$tmp/p1w1.out" "$tmp/p2w1.out" && cmp -s "$tmp/p1w1.out" "$tmp/p1w2.out" ||
    { echo "bench/mpi.sh: results differ between engines"; exit 1; }
