# stats.awk - reads one vwalls stats JSON (docs/runtime.md, Statistics) and prints the figures
# bench/experiments.sh needs as KEY=VALUE lines, so the benchmark and its ctest smoke run
# need no JSON library. It relies on the writer's layout (one top-level key per line, one
# array element per line); a change there shows up as missing keys, which the CSV checker
# (check.awk) rejects, rather than as wrong numbers.
#   usage: awk -f stats.awk STATS.json
function num(line, key,    m) {
    if (match(line, "\"" key "\": *-?[0-9.eE+-]+")) {
        m = substr(line, RSTART, RLENGTH)
        sub(/^[^:]*: */, "", m)
        return m
    }
    return ""
}
function str(line, key,    m) {
    if (match(line, "\"" key "\": *\"[^\"]*\"")) {
        m = substr(line, RSTART, RLENGTH)
        sub(/^[^:]*: *"/, "", m); sub(/"$/, "", m)
        return m
    }
    return ""
}
/^  "[a-z_]+": \[/ { arr = $1; gsub(/[":]/, "", arr); next }
/^  \]/ { arr = ""; next }
# counted work per worker (deterministic, unlike busy time): ray-cell segments for the
# ray tracer, rasterised receiver elements for radiosity. Read from the workers' own
# counters, which count a duplicated or farmed cell's work where its copies ran; a cell's
# figures are its master's and copies' totals, so summing cells onto their master
# worker gave duplicate and farm rows the work lambda of no balancing (1.514 for
# duplicate on 1000 spheres 100% clustered, 2x4, where its workers' counters say 1.08).
# The cells' figures are the fallback for stats without per-worker counters.
arr == "workers" && /"busy_s"/ {
    b = num($0, "busy_s") + 0
    busy_sum += b; if (b > busy_max) busy_max = b
    cw = num($0, "segments"); if (cw == "") cw = num($0, "rasterised_elements")
    if (cw != "") { wwork[nworkers + 0] = cw + 0; have_wwork = 1 }
    nworkers++
    next
}
arr == "cells" && /"worker"/ {
    wk = num($0, "worker") + 0
    cw = num($0, "segments"); if (cw == "") cw = num($0, "rasterised_elements")
    work[wk] += cw; if (wk + 1 > nwk) nwk = wk + 1
    next
}
arr == "processes" && /"peak_rss_bytes"/ {
    r = num($0, "peak_rss_bytes") + 0
    rss_sum += r; if (r > rss_max) rss_max = r
    if (rss_min == "" || r < rss_min) rss_min = r
    nprocs++
    next
}
/^  "engine":/ { out["kind"] = str($0, "kind"); out["processes"] = num($0, "processes"); out["workers"] = num($0, "workers") }
/^  "decomposition":/ { out["layout"] = str($0, "layout"); out["cells"] = num($0, "cells") }
/^  "balance":/ {
    out["strategy"] = str($0, "strategy")
    out["lambda"] = num($0, "imbalance")
    out["lambda_before"] = num($0, "imbalance_before")
    out["lambda_after"] = num($0, "imbalance_after")
    out["migrated"] = num($0, "migrated_objects")
    if (out["lambda"] == "") out["lambda"] = out["lambda_after"]
}
# compute includes the balancer's phase (its pre-pass traces rays too, and warms what the
# compute phase then finds warm): a balanced run is charged for its balancing
/^  "time_s":/ {
    out["compute_only"] = num($0, "compute"); out["balance_s"] = num($0, "balance")
    out["compute"] = sprintf("%.6f", out["compute_only"] + out["balance_s"]); out["total"] = num($0, "total")
}
/^  "messages":/ { out["messages"] = num($0, "count"); out["bytes"] = num($0, "bytes"); out["remote_bytes"] = num($0, "remote_bytes") }
/^  "rays":/ {
    out["segments"] = num($0, "segments")
    out["rays"] = num($0, "eye") + num($0, "reflect") + num($0, "refract") + num($0, "shadow")
}
/^  "radiosity":/ { out["shots"] = num($0, "shots"); out["unshot_ratio"] = num($0, "unshot_ratio"); out["energy_error"] = num($0, "energy_error") }
END {
    if (have_wwork) {
        nwk = nworkers
        for (i = 0; i < nwk; i++) work[i] = wwork[i]
    }
    for (i = 0; i < nwk; i++) { wsum += work[i]; if (work[i] > wmax) wmax = work[i] }
    printf "work_sum=%d\nlambda_work=%.6f\n", wsum, (wsum > 0 ? wmax * nwk / wsum : 1)
    for (k in out) print k "=" out[k]
    printf "busy_sum=%.6f\nbusy_max=%.6f\nnworkers=%d\n", busy_sum, busy_max, nworkers
    printf "rss_max_mb=%.1f\nrss_min_mb=%.1f\nrss_sum_mb=%.1f\nnprocs=%d\n", rss_max / 1048576, rss_min / 1048576, rss_sum / 1048576, nprocs
}
