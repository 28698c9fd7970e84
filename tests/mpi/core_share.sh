#!/bin/sh
# core_share.sh - the default worker count under MPI: processes of one host that may run
# on the same CPUs share its cores. Started unbound (each may run on every CPU), the 2
# processes each run half the workers one process runs alone (at least 1); an explicit
# --workers is kept, and so is VW_CORES's count (a process told its cores keeps them). The
# default balance load is the counted work where the workers outnumber that share, a
# fraction of a core when the processes outnumber the cores.
# usage: core_share.sh VWALLS SCENE FLAVOUR "MPIEXEC -n 2 [flags]"
vwalls=$1 scene=$2 flavour=$3 launch=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
if [ "$flavour" = openmpi ]; then unbound="--bind-to none"; else unbound="-bind-to none"; fi
# render [COMMAND...]: the scene rendered by COMMAND vwalls (a launcher, or nothing).
render() { "$@" "$vwalls" render "$scene" -o "$dir/x.png" --size 32x32 $opts; }
opts=""
alone=$(render 2>&1 | sed -n 's/.*workers \([0-9]*\) x 1 process.*/\1/p')
[ -n "$alone" ] || { echo "FAIL: no worker count from one process alone"; exit 1; }
half=$((alone / 2))
[ "$half" -ge 1 ] || half=1
# expect WORKERS WHAT: the summary of the job (render under the launcher, unbound)
# names WORKERS x 2 processes.
expect() {
    # shellcheck disable=SC2086
    render $launch $unbound >"$dir/out" 2>&1
    if grep -q "workers $1 x 2 processes" "$dir/out"; then
        echo "ok: $2: $1 workers a process"
    else
        echo "FAIL: $2: expected $1 workers a process:"
        cat "$dir/out"
        fail=1
    fi
}
expect "$half" "unbound, $alone alone"
opts="--workers 3"
expect 3 "unbound, --workers 3"
# The default balance load follows the same share (every process must decide alike):
# busy time on the workers the share gives, counted visits on one more, where busy
# time would be mostly waiting for a core.
load() {
    opts="--cells 2x2 --balance tensor --quiet --stats $dir/s.json $1"
    rm -f "$dir/s.json"
    # shellcheck disable=SC2086
    render $pre $launch $unbound >"$dir/out" 2>&1
    got=$(sed -n 's/.*"load_model": "\([a-z]*\)".*/\1/p' "$dir/s.json" 2>/dev/null)
    if [ "$got" = "$2" ]; then
        echo "ok: balance load $got with ${1:-the default workers}${pre:+ under $pre}"
    else
        echo "FAIL: balance load '$got' with ${1:-the default workers}${pre:+ under $pre}, expected $2:"
        cat "$dir/out"
        fail=1
    fi
}
pre=""
load "" busy
load "--workers $((half + 1))" segments
# Both processes on one CPU have half a core each: their one worker each (the least)
# is crowded, though it rounds to a whole worker.
if command -v taskset >/dev/null 2>&1; then
    pre="taskset -c 0"
    load "" segments
    pre=""
fi
opts=""
export VW_CORES=3
expect 3 "unbound, VW_CORES=3"
exit $fail
