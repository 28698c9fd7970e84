#!/usr/bin/env bash
# publish.sh - writes BENCHMARKS.md at the repository root from one experiments run (OUT:
# results.csv/.md, peers.md, run.env, the plots) and copies the plots to docs/bench/.
# The prose around the numbers is fixed; every number in it is read from this run.
#   usage: publish.sh OUT ROOT
set -euo pipefail
OUT=$1 ROOT=$2
DOCS=$ROOT/docs/bench
mkdir -p "$DOCS"
rm -f "$DOCS"/overlay-*.png
for p in efficiency.png speedup.png unshot.png "$OUT"/overlay-*.png; do
  p=$(basename "$p")
  [ -f "$OUT/$p" ] && cp "$OUT/$p" "$DOCS/$p"
done
env_() { sed -n "s/^$1=//p" "$OUT/run.env"; }
# The run's length as prose: "1 minute", "2 minutes" (rounded up).
took_min=$(( $(env_ seconds) / 60 + 1 ))
took="$took_min minute$([ "$took_min" = 1 ] || echo s)"
CSV=$OUT/results.csv
cpu=$(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo | head -1)
mem=$(awk '/^MemTotal/ { printf "%.1f GiB", $2 / 1048576 }' /proc/meminfo)
os=$(. /etc/os-release 2>/dev/null && echo "$PRETTY_NAME")

# q AWK-PROGRAM: run over results.csv with c["column"] -> index, v(name), and laid(): the
# cells of the row's layout (divide's rows end with more cells than their layout had)
q() { awk -F, -v nproc="$(env_ nproc)" "NR == 1 { for (i = 1; i <= NF; i++) c[\$i] = i; next }
  function v(k) { return \$(c[k]) }
  function laid(   d, i, n, p) { n = split(v(\"layout\"), d, \"x\"); p = 1; for (i = 1; i <= n; i++) p *= d[i]; return p }
  $1" "$CSV"; }

true_rt=$(q '$1 == "raytrace" && v("scene") ~ /^s1000-/ && v("engine") == "threads" && v("balance") == "none" && v("workers") == nproc && nproc > 1 {
  printf "%s%s on %s cells: %.2f", (n++ ? "; " : ""), v("scene"), v("layout"), v("speedup") }')
true_farm=$(q '$1 == "raytrace" && v("scene") ~ /^s1000-/ && v("engine") == "threads" && v("balance") == "farm" && nproc > 1 {
  printf "%s%s on %s cells: %.2f", (n++ ? "; " : ""), v("scene"), v("layout"), v("speedup") }')
true_rad=$(q '$1 == "radiosity" && v("engine") == "threads" && v("balance") == "none" && v("workers") == nproc && nproc > 1 {
  printf "%s%s cells: %.2f (efficiency %.2f)", (n++ ? "; " : ""), v("layout"), v("speedup"), v("efficiency") }')
# The load-balance headline: 1/lambda of the counted work (deterministic) on 8 cells and
# 8 workers, per balance and clustering. The busy-time lambda of 8 workers on fewer cores
# is mostly the time each waited for a core (tensor's 1/lambda 0.40 against none's 0.62
# on the fully clustered scenes, where the counted work said 0.69 against 0.65), so it
# goes into the headline only for rows with no more workers than cores.
lb8=$(q '$1 == "raytrace" && v("engine") == "threads" && laid() == 8 && v("workers") == 8 && v("lambda_work") > 0 {
  cl = v("scene"); sub(/.*-c/, "", cl); s[v("balance") " " cl] += 1 / v("lambda_work"); k[v("balance") " " cl]++ }
  END { for (x in s) { split(x, a, " "); printf "%s|%s|%.2f\n", a[2], a[1], s[x] / k[x] } }' | sort -t'|' -k1,1n -k2,2)
lb8_text=$(echo "$lb8" | awk -F'|' 'NF == 3 { if (!n || $1 != last) { printf "%s%s%% clustered: ", (n++ ? "; " : ""), $1 * 100; last = $1; m = 0 } printf "%s%s %s", (m++ ? ", " : ""), $2, $3 }')
lbt_text=$(q '$1 == "raytrace" && v("engine") == "threads" && v("workers") == laid() && v("workers") > 1 && v("workers") <= nproc && v("balance") != "farm" {
  cl = v("scene"); sub(/.*-c/, "", cl); s[cl "|" v("balance")] += v("lb_eff"); k[cl "|" v("balance")]++ }
  END { for (x in s) printf "%s|%.2f\n", x, s[x] / k[x] }' | sort -t'|' -k1,1n -k2,2 |
  awk -F'|' 'NF == 3 { if (!n || $1 != last) { printf "%s%s%% clustered: ", (n++ ? "; " : ""), $1 * 100; last = $1; m = 0 } printf "%s%s %s", (m++ ? ", " : ""), $2, $3 }')
bload=$(env_ balance_load)
case "${bload:-auto}" in
  auto) bload_text="\`--balance-load segments\` (counted ray-cell visits) on rows with more workers than cores, the default busy time on the others" ;;
  *) bload_text="\`--balance-load $bload\` on every balanced row" ;;
esac
segs=$(q '$1 == "raytrace" && v("engine") == "threads" && v("balance") == "none" && v("workers") == v("cells") {
  if (v("cells") == 1) one[v("scene")] = v("work"); if (v("cells") == 8) eight[v("scene")] = v("work") }
  END { for (s in one) if (s in eight) { r += eight[s] / one[s]; n++ } if (n) printf "%.2f", r / n }')
rad8=$(q '$1 == "radiosity" && v("balance") == "none" && v("workers") == 8 {
  printf "%s%s: speedup %.2f, 1/lambda %.2f, %d shots", (n++ ? "; " : ""), v("engine"), v("speedup"), v("lb_eff"), v("work") }')
rad1=$(q '$1 == "radiosity" && v("cells") == 1 && v("workers") == 1 { printf "%.1f s, %d shots", v("compute_s"), v("work") }')
# means over the sphere scenes at 8 cells on 8 workers, per balance: eff, 1/lambda, model
m8() { q '$1 == "'"$1"'" && v("engine") == "'"$2"'" && v("workers") == 8 && v("balance") == "'"$3"'" {
  e += v("efficiency"); l += v("lb_eff"); m += v("eff_model"); n++ }
  END { if (n) printf "%.2f %.2f %.2f", e / n, l / n, m / n; else printf "n/a n/a n/a" }'; }
read -r rt_e rt_l rt_m <<< "$(m8 raytrace threads none)"
read -r rtb_e rtb_l rtb_m <<< "$(m8 raytrace threads "$(env_ balance | cut -d' ' -f1)")"
read -r rtm_e rtm_l rtm_m <<< "$(m8 raytrace mpi none)"
read -r rd_e rd_l rd_m <<< "$(m8 radiosity threads none)"
read -r rdm_e rdm_l rdm_m <<< "$(m8 radiosity mpi none)"
rt_model_best=$(q '$1 == "raytrace" && v("workers") == 8 { if (v("eff_model") > b) { b = v("eff_model"); w = v("scene") " " v("balance") } } END { printf "%.2f (%s)", b, w }')
# balanced against unbalanced, same scene and layout: rows where 1/lambda rose
bal_better=$(q '$1 == "raytrace" && v("engine") == "threads" && v("workers") == laid() {
  k = v("scene") "/" v("layout"); if (v("balance") == "none") u[k] = v("lb_eff"); else b[k, ++nb[k]] = v("lb_eff") }
  END { for (k in nb) if (k in u) for (i = 1; i <= nb[k]; i++) { n++; if (b[k, i] > u[k]) up++ } printf "%d of %d", up, n }')
# how much of a core the one-worker runs got (CPU / wall): the rest went to other jobs
cpu_share=$(q 'v("workers") == 1 && v("engine") == "threads" && v("wall_s") > 0 { s += v("cpu_s") / v("wall_s"); n++ }
  END { if (n) printf "%.0f%%", 100 * s / n }')
mem8=$(awk -F, '$1 == "mpi" && $2 == 8 { print $9 }' "$OUT/memory.csv" 2>/dev/null)
pov1=$(awk -F, '$1 == "povray" && $3 == 1 { printf "%s%s", (n++ ? ", " : ""), $6 }' "$OUT/peers.csv" 2>/dev/null)
raw1=$(awk -F, '$1 == "embree_raw" { printf "%s%s", (n++ ? ", " : ""), $6 }' "$OUT/peers.csv" 2>/dev/null)
bal_note="Load balancing (\`--balance\`) was not in this build of \`vwalls render\`: the table has no balanced rows yet; re-run to add them."
[ "$(env_ have_balance)" = 1 ] && bal_note="Balanced rows use \`--balance $(env_ balance)\` (all five strategies on the hardest case: 1000 spheres, 100% clustered, 2x4) with $bload_text: a worker's busy time on an oversubscribed machine is mostly time spent waiting for a core, and a balancer given it balances the scheduler's noise; \`lambda_before\` is the imbalance the balancer measured before moving walls. **λ work** counts each worker's own segments, so a duplicated or farmed cell's work is where its copies ran."

{
cat <<EOF
# Benchmarks: the paper's evaluation, reproduced

The experiments of Menzel et al. (1994) — ray tracing of 100, 500 and 1000 spheres,
uniform and 50%/100% clustered, and radiosity of a room of about 3600 patches, on cell
layouts 1x1, 1x2, 2x2, 2x3 and 2x4 with one cell per processor — run again on vwalls,
with the threads engine and (a subset) under \`mpirun\`, beside POV-Ray 3.7, Embree's raw
ray-casting loop, and per-process memory under MPI. Everything below comes from one run
on the machine described here; nothing is edited by hand but this file's fixed prose.

Regenerate (about ${took} here; writes \`out/experiments/\`, this file and \`docs/bench/*.png\`):

\`\`\`sh
./run bench experiments --publish        # = bench/experiments.sh --publish
bench/experiments.sh --smoke             # the ctest version (label bench): seconds
\`\`\`

## Machine and run

- $(env_ nproc) cores (\`nproc\`), $cpu, $mem memory; $os
- shared with other engineers: load average $(env_ load_start) at the start of the run,
  $(env_ load_end) at the end — wall times are noisy, each render row is the best of
  $(env_ repeat) runs (radiosity and MPI rows fewer), and the deterministic columns matter more;
  the one-worker runs got on average $cpu_share of a core (CPU time / wall time; the rest
  of their wall time went to other jobs)
- run $(env_ date), commit $(env_ commit), $(env_ seconds) s; images $(env_ size)x$(env_ size),
  depth 5, the cells mapped onto the workers as the paper does (\`--farm none\`: rays cross
  between workers as messages; \`vwalls render\` by default farms a process's cells among
  its workers, see docs/balancing.md); the walls divide the sphere scenes' space, the cube
  [0,10]^3 \`vwalls gen spheres\` fills (\`--world 0,0,0,10,10,10\`), so a clustered scene
  loads the cells of its cluster, as in the paper (the objects' own bounds, the default
  world box, would be the cluster's at 100%); radiosity of \`vwalls gen room\` with patch size 0.21 (3614 pieces on 1 cell) stops at
  unshot/emitted < $(env_ rsf)

## How to read the table

- **compute s** is the compute phase plus the balancing phase when there is one (the
  balancer's pre-pass traces rays too). **speedup** = the fastest sequential run's compute
  (1 worker, threads engine: 1 cell, or the walls on one worker if that is faster, as the
  paper divides by the fastest sequential time) / this row's; **eff.** = speedup / workers
  (of all processes). **whole s** and the CSV's \`speedup_whole\` are the same for the
  whole process (load, build, compute, write), best of the runs.
- **\*** after the speedup: more workers than cores. There the speedup measures this
  $(env_ nproc)-core machine (it cannot exceed $(env_ nproc)), not the method. Read
  **λ** instead: the max/mean of the workers' busy time (\`balance.imbalance\` in the
  stats JSON), and **1/λ**, the load-balance efficiency — on enough cores, efficiency is at
  most 1/λ, whatever the machine. Busy times are wall-clock intervals, so on an
  oversubscribed machine they include time a worker was descheduled: λ is then only
  indicative.
- **λ work** is λ of counted work instead of time (ray segments or rasterised elements
  per worker: deterministic), and **eff. model** = least sequential counted work / this
  row's counted work / λ work: the efficiency dedicated cores would reach if time were
  proportional to counted work (see "Against the paper").
- **busy Σ** is the total busy time of all workers; **CPU** the user+system time of the
  whole process tree (bash \`time\`, includes MPI's polling); **work** is deterministic:
  ray segments (a ray crossing a wall is one more segment) for ray tracing, shots for
  radiosity; **msgs** and **MB sent** are the runtime's messages; **RSS** is peak RSS of
  the largest process and the sum over processes.
- $bal_note
- **balance** \`farm\`: no balancing, the cells farmed among the workers (\`--farm all\`);
  every other row maps the cells onto the workers (\`--farm none\`).

## Headline figures

- **True speedup on this machine's $(env_ nproc) cores**, ray tracing, 1000 spheres, the
  cells mapped onto the workers: ${true_rt:-n/a}; farmed (\`--farm all\`, every worker
  holding every cell: what \`vwalls render\` does by default): ${true_farm:-n/a}.
- **Radiosity, $(env_ nproc) workers**: ${true_rad:-n/a}; on 8 workers: ${rad8:-n/a}
  (sequential: $rad1).
- **Load-balance efficiency on 8 cells, 8 workers: 1/λ of the counted work** (ray segments
  per worker, no timer; divide's split further; mean over 100/500/1000 spheres): ${lb8_text:-n/a}.
  On enough cores the efficiency is at most this. The busy-time λ of these rows is not a
  headline here: 8 workers share $(env_ nproc) cores, so a worker's busy time is mostly the time it
  waited for one. Busy-time 1/λ where the workers are no more than the cores (2 cells on
  2 workers): ${lbt_text:-n/a}.
- **Model efficiency on 8 cells** (counted work, no timer; mean over the sphere scenes):
  ray tracing $rt_m unbalanced, $rtb_m balanced; radiosity $rd_m (paper: ~1 and 0.68).
- **Cost of the walls**: 8 cells trace ${segs:-n/a}× the ray segments of 1 cell (every
  wall crossing is a message and a new traversal in the next cell).

## Results

EOF
cat "$OUT/results.md"
cat <<EOF

Full figures (all columns): \`out/experiments/results.csv\` after a run.

## Plots

![efficiency against cells](docs/bench/efficiency.png)

![speedup against cells](docs/bench/speedup.png)

![radiosity convergence](docs/bench/unshot.png)

EOF
if ls "$DOCS"/overlay-*.png >/dev/null 2>&1; then
  echo "Per-cell load, 1000 spheres 100% clustered on 2x4 cells (each cell's pixels tinted"
  echo "by its measured load, green light to red heavy):"
  echo
  for p in "$DOCS"/overlay-*.png; do
    b=$(basename "$p" .png); b=${b#overlay-}
    echo "| balance: $b |"
  done | paste -sd' ' | sed 's/| |/|/g'
  for _ in "$DOCS"/overlay-*.png; do echo "|---|"; done | paste -sd' ' | sed 's/| |/|/g'
  for p in "$DOCS"/overlay-*.png; do echo "| ![](docs/bench/$(basename "$p")) |"; done | paste -sd' ' | sed 's/| |/|/g'
  echo
fi
cat <<EOF
## Peers and limits

POV-Ray is timed as a whole process (parse, build, render, write) against a whole
\`vwalls render\` process on 1 cell with the same number of threads, on the scene
\`bench/nff2pov.py\` converts (polygons of more than three corners as POV-Ray polygons,
\`pp\` ones by ear clipping, so concave ones cover what vwalls covers: test
\`bench_nff2pov_concave\`; the \`#vw Ks\` and \`#vw Ke\` extension lines as far as POV-Ray's
finish can follow them, saying on stderr where it cannot: test \`bench_nff2pov_ext\`);
Embree's raw loop
(\`vw_bench_embree_raw\`: the same ray tree by plain rtcIntersect1/rtcOccluded1 recursion)
against vwalls' compute phase on 1 cell and 1 worker. The two count rays differently (the
raw loop counts every eye ray, vwalls only those entering the world box), so compare
times, not rates. Memory: peak RSS per process on a uniform scene large enough that the
scene, not the binary and image, dominates.

EOF
cat "$OUT/peers.md" 2>/dev/null || echo "(peers not measured in this run)"
cat <<EOF

## Against the paper

| | paper (1994) | vwalls here: measured eff. | 1/λ (busy) | model eff. (counted work) |
|---|---|--:|--:|--:|
| ray tracing, 8 cells, threads | close to 1 on 8 shared-memory processors | $rt_e | $rt_l | $rt_m |
| ray tracing, 8 cells, threads, balanced | | $rtb_e | $rtb_l | $rtb_m |
| ray tracing, 8 cells, 8 MPI processes | | $rtm_e | $rtm_l | $rtm_m |
| radiosity, 8 cells, threads | | $rd_e | $rd_l | $rd_m |
| radiosity, 8 cells, 8 MPI processes | 0.68 on 8 workstations | $rdm_e | $rdm_l | $rdm_m |

Means over the sphere scenes (all nine for threads, the two MPI ones for MPI). "Model
eff." is the CSV's \`eff_model\`: least sequential counted work / this run's counted work
/ λ of the counted work over the workers — what dedicated cores would give if time were
proportional to ray segments (ray tracing) or rasterised elements (radiosity). It needs
no timer, so it means the same on a laptop or a cluster; it ignores message latency,
which a real network adds, and counts every segment as equally costly.

What this says, honestly:

- **The measured efficiencies do not reproduce the paper, and cannot here.** This
  machine has $(env_ nproc) cores shared with other jobs (load $(env_ load_start) at the start); with 8
  workers the efficiency is bounded by $(env_ nproc)/8 before the method loses anything. Even the
  true-speedup rows (2 workers on 2 cores) mostly stay below 1: the compute phases of
  these scenes last tens of milliseconds, so thread start-up, termination waves and the
  other jobs' noise weigh as much as the work.
- **Ray tracing: a wall costs more now than in 1994.** Counted work says so without any
  timer: 8 cells trace ${segs:-?}× the ray segments of 1 cell, because every wall a ray
  crosses ends one segment and starts another (a new traversal in the next cell, and a
  message when that cell is on another worker; on the same worker the ray is handed on
  inline). When a ray-object test cost far more than a message, that overhead
  vanished; with Embree a segment costs well under a microsecond, so the per-crossing
  cost is of the order of the tracing itself. The model efficiency at 8 cells ($rt_m
  unbalanced, $rtb_m balanced; best $rt_model_best) is the figure to hold against the
  paper's ~1: the gap is the price of a wall crossing relative to a ray, plus imbalance.
- **Load balance**: clustered scenes are where 1/λ falls (the paper's reason for moving
  walls); balancing raised 1/λ in $bal_better balanced rows against the same scene and
  layout unbalanced (the balancer's pre-pass and moved walls are charged to its time). Busy-time λ on an oversubscribed machine
  includes time a worker was descheduled, so the counted-work λ (\`lambda_work\`) is the
  steadier of the two.
- **Radiosity** ships bitmaps, never geometry, and its counted work does not grow with
  the cells (shots fall a little as more cells shoot per round): its model efficiency at
  8 cells, $rd_m, is set almost entirely by imbalance, and is the figure to compare with
  the paper's 0.68 on 8 workstations. Its measured time on 8 MPI processes here is that
  of an oversubscribed machine, not of a network.
- **Peers**: POV-Ray 3.7 takes ${pov1:-n/a}× vwalls' time on the 1000-sphere scenes with
  one thread (whole processes; at this size POV-Ray's start-up and parsing weigh much).
  Embree's raw loop over the same ray tree (one thread, no cells) took ${raw1:-n/a}×
  vwalls' compute phase on 1 cell: below 1, the difference is the framework's cost when
  there are no walls (ray packets, the pixel bookkeeping, the runtime loop). The two count
  rays differently (the raw loop also traces the eye rays that miss the world box, which
  vwalls never starts) and both last tens of milliseconds, so take it as a rough bound.
- **Memory**: with 8 MPI processes each process's peak RSS is ${mem8:-n/a}× one process's
  on the 200000-sphere scene, where 1/8 would be the ideal: every process still reads and
  places the whole scene before keeping its own cells (as \`bench/mpi.sh\` notes), and
  that load, not the cells, sets the peak; the sum over processes grows with P.

## What is missing

- Speedups beyond $(env_ nproc) workers need a machine with more cores: run the same command there.
- The MPI rows run on one machine (oversubscribed): no network latency is in them.
- Radiosity has no balancing rows (\`vwalls radiosity\` has no \`--balance\`). On the tiny
  Cornell box (smoke run) the MPI engine's radiosity compute phase comes out a fraction of
  the threads engine's for the same shots, so the smoke run leaves MPI radiosity out.
EOF
} > "$ROOT/BENCHMARKS.md.tmp"
mv "$ROOT/BENCHMARKS.md.tmp" "$ROOT/BENCHMARKS.md"
echo "publish: $ROOT/BENCHMARKS.md, $DOCS" >&2
