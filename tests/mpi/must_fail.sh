# must_fail.sh - sourced by the MPI tests of a job that must fail, not hang (fault.sh,
# local_fail.sh, wire.sh).
# must_fail NAME LIMIT_S TIMEOUT_S COMMAND...: runs COMMAND under `timeout TIMEOUT_S`,
# its output in the file $out (printed, then left for the caller's checks and removal),
# and sets rc (its status), ms (its wall time) and fail: 1 when the job succeeded, hung
# (killed by the timeout) or took more than LIMIT_S seconds, else 0.
# Both times count beyond base_ms, when the caller has set it (startup_ms).
must_fail() {
    name=$1 limit=$2 tmo=$3
    shift 3
    base=${base_ms:-0}
    out=$(mktemp)
    start=$(date +%s%N)
    timeout "$((tmo + (base + 999) / 1000))" "$@" >"$out" 2>&1
    rc=$?
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
    cat "$out"
    echo "$name: status $rc after $ms ms (MPI's start and end alone: $base ms)"
    fail=0
    [ "$rc" -ne 0 ] || { echo "$name: FAIL: the job succeeded"; fail=1; }
    [ "$rc" -ne 124 ] || { echo "$name: FAIL: the job hung (killed by timeout)"; fail=1; }
    [ "$ms" -le $((limit * 1000 + base)) ] ||
        { echo "$name: FAIL: took $ms ms, more than $limit s beyond MPI's start and end ($base ms)"; fail=1; }
}
# startup_ms COMMAND...: the wall time in ms of COMMAND, a job whose processes start MPI
# and end it doing nothing else. Where the host's name does not resolve at once (no
# /etc/hosts line for it, and a resolver that answers late) every process's MPI_Init
# waits seconds for it; the time limits above are about the job, so they count beyond.
startup_ms() {
    s=$(date +%s%N)
    timeout 120 "$@" >/dev/null 2>&1
    e=$(date +%s%N)
    echo $(( (e - s) / 1000000 ))
}
