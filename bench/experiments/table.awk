# table.awk - the results CSV as a Markdown table (the columns a reader compares; the CSV
# has them all). "*" after the speedup marks rows with more workers than cores, where
# speedup and efficiency measure this machine, not the method: read lambda there, and
# lambda_work / eff_model, which come from counted work and do not depend on timing.
#   usage: awk -F, -f table.awk results.csv > results.md
NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; 
    print "| app | scene | layout | engine | P×W | balance | compute s | whole s | speedup | eff. | λ | 1/λ | λ work | eff. model | busy Σ s | CPU s | work | msgs | MB sent | RSS MB max/Σ |"
    print "|---|---|---|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
    next }
function v(k) { return $(c[k]) }
{
    mark = v("cores_ok") == "yes" ? "" : "*"
    printf "| %s | %s | %s | %s | %d×%d | %s | %.3f | %.3f | %.2f%s | %.2f | %.3f | %.2f | %.3f | %.2f | %.3f | %.2f | %d | %d | %.1f | %s/%s |\n",
        v("app"), v("scene"), v("layout"), v("engine"), v("processes"), v("workers") / v("processes"), v("balance"),
        v("compute_s"), v("wall_s"), v("speedup"), mark, v("efficiency"), v("lambda"), v("lb_eff"), v("lambda_work"), v("eff_model"),
        v("busy_sum_s"), v("cpu_s"), v("work"), v("messages"), v("bytes") / 1e6, v("rss_max_mb"), v("rss_sum_mb")
}
