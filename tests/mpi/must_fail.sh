# must_fail.sh - sourced by the MPI tests of a job that must fail, not hang (fault.sh,
# local_fail.sh, wire.sh).
# must_fail NAME LIMIT_S TIMEOUT_S COMMAND...: runs COMMAND under `timeout TIMEOUT_S`,
# its output in the file $out (printed, then left for the caller's checks and removal),
# and sets rc (its status), ms (its wall time) and fail: 1 when the job succeeded, hung
# (killed by the timeout) or took more than LIMIT_S seconds, else 0.
must_fail() {
    name=$1 limit=$2 tmo=$3
    shift 3
    out=$(mktemp)
    start=$(date +%s%N)
    timeout "$tmo" "$@" >"$out" 2>&1
    rc=$?
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
    cat "$out"
    echo "$name: status $rc after $ms ms"
    fail=0
    [ "$rc" -ne 0 ] || { echo "$name: FAIL: the job succeeded"; fail=1; }
    [ "$rc" -ne 124 ] || { echo "$name: FAIL: the job hung (killed by timeout)"; fail=1; }
    [ "$ms" -le $((limit * 1000)) ] || { echo "$name: FAIL: took $ms ms, more than $limit s"; fail=1; }
}
