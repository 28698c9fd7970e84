#!/bin/sh
# same_stats.sh - example-pairs under MPI gives the threads engine's results: the same
# count, the same module counters, the same messages into every cell (from the stats
# JSON), and the MPI run reports bytes that crossed processes.
# usage: same_stats.sh VWALLS "MPIEXEC -n P [flags]"
vwalls=$1 launch=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
args="example-pairs --spheres 4000 --radius 0.03 --seed 11 --cells 4x2x2 --workers 2 --quiet"
# shellcheck disable=SC2086
"$vwalls" $args --stats "$dir/threads.json" >"$dir/threads.out" || exit 1
# shellcheck disable=SC2086
$launch "$vwalls" $args --stats "$dir/mpi.json" >"$dir/mpi.out" || exit 1
# The job's and the cells' lines (the workers' lines, which carry their own counters,
# differ with the worker count).
pick() { grep -E '"counters"|"messages_in"' "$1" | grep -v '"process": ' |
         sed -e 's/"busy_s": [0-9.e+-]*//' -e 's/"load": [0-9.e+-]*//' -e 's/"worker": [0-9]*//'; }
pick "$dir/threads.json" >"$dir/threads.pick"
pick "$dir/mpi.json" >"$dir/mpi.pick"
fail=0
cmp -s "$dir/threads.out" "$dir/mpi.out" || { echo "count differs:"; cat "$dir/threads.out" "$dir/mpi.out"; fail=1; }
diff "$dir/threads.pick" "$dir/mpi.pick" || { echo "counters or per-cell messages differ"; fail=1; }
grep -q '"kind": "mpi"' "$dir/mpi.json" || { echo "stats do not say engine mpi"; fail=1; }
grep -Eq '"remote_bytes": [1-9]' "$dir/mpi.json" || { echo "no remote bytes reported"; fail=1; }
echo "pairs: $(cat "$dir/mpi.out"); $(grep -c '"messages_in"' "$dir/mpi.json") cells compared"
exit $fail
