#!/bin/sh
# print_once.sh - under mpirun only the first process prints: a command's standard
# output (help, version, info, a scene gen writes to stdout, a render's summary) is the
# same as the single process's, not one copy per rank.
# usage: print_once.sh VWALLS SCENE "MPIEXEC -n P [flags]"
vwalls=$1 scene=$2 launch=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
check() {
    "$vwalls" "$@" >"$dir/single" 2>/dev/null
    # shellcheck disable=SC2086
    $launch "$vwalls" "$@" >"$dir/mpi" 2>"$dir/mpi.err"
    if cmp -s "$dir/single" "$dir/mpi"; then
        echo "ok: vwalls $* ($(wc -l <"$dir/single") lines)"
    else
        echo "FAIL: vwalls $*: $(wc -l <"$dir/single") lines alone, $(wc -l <"$dir/mpi") under mpirun"
        fail=1
    fi
}
check --version
check --help
check help info
check render --help
check info "$scene" --objects
check gen balls --size 2
check example-pairs --spheres 500 --quiet --workers 1
exit $fail
