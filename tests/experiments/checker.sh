#!/bin/sh
# checker.sh - the experiments CSV checker (bench/experiments/check.awk) must accept a
# good CSV and reject each deliberately bad one, for the stated reason: a checker that
# passes everything would let the smoke test pass on garbage.
#   usage: checker.sh CHECK_AWK DIR
set -u
check=$1 dir=$2
fails=0
expect() { # expect FILE STATUS MESSAGE-SUBSTRING
    out=$(awk -F, -f "$check" "$dir/$1" 2>&1)
    st=$?
    if [ "$st" != "$2" ]; then
        echo "FAIL: $1: exit $st, expected $2"; echo "$out"; fails=$((fails + 1))
    elif ! printf '%s\n' "$out" | grep -q -- "$3"; then
        echo "FAIL: $1: output lacks '$3':"; echo "$out"; fails=$((fails + 1))
    else
        echo "ok: $1 -> $st ($3)"
    fi
}
expect good.csv 0 "ok: 15 rows"
expect bad-header.csv 1 "header is not the expected columns"
expect bad-width.csv 1 "row has 29 fields"
expect bad-baseline.csv 1 "is not the fastest sequential compute_s / compute_s = 1.032"
expect bad-lambda.csv 1 "lambda below 1"
expect bad-speedup.csv 1 "speedup is not positive"
expect bad-number.csv 1 "compute_s is not a number"
expect bad-noseq.csv 1 "no sequential row"
expect bad-empty.csv 1 "no rows"
expect bad-model.csv 1 "eff_model above 1"
[ "$fails" = 0 ]
