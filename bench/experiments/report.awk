# report.awk - turns raw.tsv (one line per row of the experiment: tab-separated KEY=VALUE
# pairs from stats.awk plus the run's wall and CPU time) into the results CSV. Speedup is
# against the fastest sequential run of the same application and scene (1 worker, threads
# engine, no balancing, any layout: the paper divides by the fastest sequential time);
# efficiency is speedup / workers (of all processes); eff_model is the bound from counted
# work, which does not depend on timing (see the comment below).
#   usage: awk -v nproc=N -f report.awk raw.tsv > results.csv
BEGIN { FS = "\t" }
{
    n++
    for (i = 1; i <= NF; i++) {
        if ($i == "") continue
        k = $i; sub(/=.*/, "", k)
        val = $i; sub(/^[^=]*=/, "", val)
        r[n, k] = val
    }
    key = r[n, "app"] "/" r[n, "scene"]
    if (r[n, "workers"] == 1 && r[n, "engine"] == "threads" && r[n, "bal"] == "none") {
        if (!(key in seq) || r[n, "compute"] + 0 < seq[key]) seq[key] = r[n, "compute"] + 0
        # the least counted work of any sequential run (deterministic, unlike the fastest)
        if (!(key in seqk) || r[n, "work_sum"] + 0 < seqk[key]) seqk[key] = r[n, "work_sum"] + 0
        if (!(key in seqw) || r[n, "wall"] + 0 < seqw[key]) seqw[key] = r[n, "wall"] + 0
    }
}
function f(x, d) { return sprintf("%." d "f", x) }
END {
    print "app,scene,layout,cells,engine,processes,workers,balance,repeat,compute_s,total_s,wall_s,speedup,efficiency,speedup_whole,lambda,lb_eff,lambda_before,busy_sum_s,busy_max_s,cpu_s,work,messages,bytes,remote_bytes,rss_max_mb,rss_sum_mb,cores_ok,lambda_work,eff_model"
    for (i = 1; i <= n; i++) {
        key = r[i, "app"] "/" r[i, "scene"]
        c = r[i, "compute"] + 0; w = r[i, "wall"] + 0
        sp = (key in seq && c > 0) ? seq[key] / c : 0
        spw = (key in seqw && w > 0) ? seqw[key] / w : 0
        workers = r[i, "workers"] + 0
        lam = r[i, "lambda"] + 0
        work = (r[i, "app"] == "raytrace") ? r[i, "segments"] : r[i, "shots"]
        lw = r[i, "lambda_work"] + 0; ws = r[i, "work_sum"] + 0
        # the efficiency P dedicated cores would reach if time were proportional to the
        # counted work: (least sequential work / this row's work) / (its counted imbalance)
        em = (key in seqk && ws > 0 && lw > 0) ? seqk[key] / ws / lw : 0
        printf "%s,%s,%s,%d,%s,%d,%d,%s,%d,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%s,%d,%d,%d,%d,%s,%s,%s,%s,%s\n",
            r[i, "app"], r[i, "scene"], r[i, "layout"], r[i, "cells"], r[i, "engine"],
            r[i, "processes"], workers, r[i, "bal"], r[i, "repeat"],
            f(c, 4), f(r[i, "total"], 4), f(w, 3), f(sp, 3), f(workers ? sp / workers : 0, 3), f(spw, 3),
            f(lam, 3), f(lam > 0 ? 1 / lam : 0, 3), f(r[i, "lambda_before"], 3),
            f(r[i, "busy_sum"], 4), f(r[i, "busy_max"], 4), f(r[i, "cpu"], 3), work,
            r[i, "messages"], r[i, "bytes"], r[i, "remote_bytes"],
            r[i, "rss_max_mb"], r[i, "rss_sum_mb"], (workers <= nproc ? "yes" : "no"), f(lw, 3), f(em, 3)
    }
}
