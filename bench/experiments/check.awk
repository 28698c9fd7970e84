# check.awk - rejects an experiments CSV (bench/experiments.sh) that is malformed or
# whose figures cannot be right: the header must be exactly the expected columns, every
# row as wide as the header, times and counts numeric and non-negative, speedup > 0 and
# equal to the fastest sequential compute_s of its (app, scene) over its own compute_s
# (report.awk's definition: a wrong baseline shows here), efficiency = speedup / workers
# (workers counts every process's), lambda and lambda_work >= 1 (max/mean can never be
# below 1), 1/lambda and eff_model <= 1, and every (app, scene) with parallel rows must
# also have a sequential row (1 worker, threads). No bound on a timing itself: a shared
# machine's noise moves a measured efficiency by tens of percent (the smoke run's
# efficiency bound failed under load), and the consistency above is what a bug breaks.
# Prints every problem and exits 1; prints "ok: N rows" and exits 0 otherwise.
#   usage: awk -F, -f check.awk results.csv
BEGIN {
    want = "app,scene,layout,cells,engine,processes,workers,balance,repeat,compute_s,total_s,wall_s,speedup,efficiency,speedup_whole,lambda,lb_eff,lambda_before,busy_sum_s,busy_max_s,cpu_s,work,messages,bytes,remote_bytes,rss_max_mb,rss_sum_mb,cores_ok,lambda_work,eff_model"
    nwant = split(want, col, ",")
    for (i = 1; i <= nwant; i++) idx[col[i]] = i
    bad = 0
}
function fail(msg) { printf "%s:%d: %s\n", FILENAME, FNR, msg; bad++ }
function isnum(s) { return s ~ /^-?[0-9]+(\.[0-9]*)?([eE][-+]?[0-9]+)?$/ }
function v(name) { return $(idx[name]) }
FNR == 1 {
    if ($0 != want) { fail("header is not the expected columns:\n  got  " $0 "\n  want " want); exit 1 }
    next
}
/^[ \t]*$/ { next }
{
    rows++
    if (NF != nwant) { fail("row has " NF " fields, header has " nwant); next }
    for (i = 4; i <= nwant; i++) {
        if (col[i] == "engine" || col[i] == "balance" || col[i] == "cores_ok") continue
        if (!isnum($i)) { fail(col[i] " is not a number: '" $i "'"); continue }
        if ($i + 0 < 0) fail(col[i] " is negative: " $i)
    }
    if (v("app") !~ /^(raytrace|radiosity)$/) fail("unknown app '" v("app") "'")
    if (v("engine") !~ /^(threads|mpi)$/) fail("unknown engine '" v("engine") "'")
    if (v("cores_ok") !~ /^(yes|no)$/) fail("cores_ok is '" v("cores_ok") "', not yes or no")
    if (!(v("compute_s") + 0 > 0)) fail("compute_s is not positive: " v("compute_s"))
    if (!(v("speedup") + 0 > 0)) fail("speedup is not positive: " v("speedup"))
    want_eff = v("speedup") / v("workers")
    if (v("efficiency") - want_eff > 0.002 || want_eff - v("efficiency") > 0.002)
        fail("efficiency " v("efficiency") " is not speedup / workers = " want_eff)
    if (v("lambda") + 0 < 0.9999) fail("lambda below 1: " v("lambda"))
    if (v("lb_eff") + 0 > 1.0001) fail("1/lambda above 1: " v("lb_eff"))
    if (v("lambda_work") + 0 < 0.9999) fail("lambda_work below 1: " v("lambda_work"))
    if (v("eff_model") + 0 > 1.0001) fail("eff_model above 1: " v("eff_model"))
    if (v("workers") + 0 < 1 || v("processes") + 0 < 1) fail("no workers or processes")
    key = v("app") "/" v("scene")
    if (v("workers") == 1 && v("engine") == "threads" && v("balance") == "none") {
        if (!(key in seq) || v("compute_s") + 0 < seq[key]) seq[key] = v("compute_s") + 0
    } else {
        par[key] = 1
    }
    # for the speedup's check, once every sequential row is known
    rkey[rows] = key; rline[rows] = FNR; rsp[rows] = v("speedup") + 0; rc[rows] = v("compute_s") + 0
}
END {
    if (bad == 0 && rows == 0) { printf "%s: no rows\n", FILENAME; bad++ }
    for (k in par) if (!(k in seq)) { printf "%s: %s has parallel rows but no sequential row\n", FILENAME, k; bad++ }
    # report.awk divides the unrounded times; the CSV has compute_s to 4 decimals (half a
    # unit of 1e-4 off in each time) and speedup to 3: that much, no more
    for (i = 1; i <= rows; i++) {
        if (!(rkey[i] in seq) || !(rc[i] > 0)) continue
        want_sp = seq[rkey[i]] / rc[i]
        d = rsp[i] - want_sp
        if (d < 0) d = -d
        if (d > 0.0005 + want_sp * (0.00005 / seq[rkey[i]] + 0.00005 / rc[i]) * 1.01 + 1e-9) {
            printf "%s:%d: speedup %s is not the fastest sequential compute_s / compute_s = %.3f\n",
                FILENAME, rline[i], rsp[i], want_sp
            bad++
        }
    }
    if (bad) exit 1
    printf "ok: %d rows\n", rows
}
