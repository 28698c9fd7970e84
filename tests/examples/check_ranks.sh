#!/bin/sh
# check_ranks.sh - under mpirun, a --check that fails (forced with
# VW_FAULT=example-mismatch) ends every process of example-pairs and example-components
# with status 1, not the output process alone (only it compares with the sequential
# result), and says so once; a --check that passes ends every process with 0. Each rank's
# status is written by a wrapper shell, one file a rank, which itself exits 0: a
# launcher ends the other ranks once one exits non-zero, and mpirun's own status (1 when
# any rank failed) says nothing of the others. First, that this test sees a failure of
# rank 0 alone for what it is (a command that exits 1 on rank 0 and 0 elsewhere).
#   usage: check_ranks.sh VWALLS NP "MPIEXEC -n NP [flags]"
set -u
vwalls=$1 np=$2 launch=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
# (expanded by each rank's shell, not here)
# shellcheck disable=SC2016
rank='${OMPI_COMM_WORLD_RANK:-${PMI_RANK:-unknown}}'

# statuses NAME WANT SHELL_COMMAND: every rank runs SHELL_COMMAND and writes its status
# into $dir/NAME.RANK; each of the NP ranks must have written WANT. Returns 0 when they
# all did, 1 (with what each said) otherwise.
statuses() {
    name=$1 want=$2 cmd=$3
    rm -f "$dir/$name".*
    # shellcheck disable=SC2086
    timeout 100 $launch sh -c "$cmd; echo \$? > \"$dir/$name.$rank\"; exit 0" >"$dir/out" 2>&1
    rc=$?
    bad=0 r=0 said=""
    [ "$rc" -ne 124 ] || { said="$said; the job hung (killed by timeout)"; bad=1; }
    while [ "$r" -lt "$np" ]; do
        if [ ! -s "$dir/$name.$r" ]; then
            said="$said; rank $r wrote no status"
            bad=1
        else
            s=$(cat "$dir/$name.$r")
            said="$said; rank $r: $s"
            [ "$s" = "$want" ] || bad=1
        fi
        r=$((r + 1))
    done
    [ -z "$(find "$dir" -name "$name.unknown")" ] || { said="$said; a rank did not know its number"; bad=1; }
    msg="$name: expected $want on every rank${said}"
    return $bad
}

# The test's own sense: rank 0 failing alone is a failure of this test.
if statuses self 1 "test \"$rank\" != 0"; then
    echo "FAIL: self-test: a failure of rank 0 alone passed ($msg)"
    exit 1
fi
echo "ok: rank 0 failing alone is seen ($msg)"

for c in example-pairs example-components; do
    if statuses "$c-fail" 1 "VW_FAULT=example-mismatch \"$vwalls\" $c --spheres 400 --radius 0.05 \
                --cells 2x2x2 --workers 1 --check --quiet"; then
        n=$(grep -c "^vwalls $c: distributed .* differs" "$dir/out")
        if [ "$n" -eq 1 ]; then
            echo "ok: $msg"
        else
            echo "FAIL: $c: the failed check said $n times, not once"
            fail=1
        fi
    else
        echo "FAIL: $msg"
        fail=1
    fi
    if statuses "$c-pass" 0 "\"$vwalls\" $c --spheres 400 --radius 0.05 --cells 2x2x2 \
                --workers 1 --check --quiet"; then
        echo "ok: $msg"
    else
        echo "FAIL: $msg"
        fail=1
    fi
    [ "$fail" -eq 0 ] || sed 's/^/    /' "$dir/out"
done
exit $fail
