/* stats.c - the stats JSON of docs/runtime.md, Statistics (a contract: tests, benchmarks and
 * pictures read it). Written by the output process through vw_outfile (a temporary
 * name, renamed), so a reader never sees half a file.
 */
#include "core/world_internal.h"
#include "vwalls/outfile.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

/* Every double goes through num(): JSON has no NaN nor infinity, and one "nan" makes
   the whole file unreadable (the 0 stands for "not measured"). */
static double num(double x) { return isfinite(x) ? x : 0.0; }

static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\')
            fprintf(f, "\\%c", ch);
        else if (ch < 0x20)
            fprintf(f, "\\u%04x", ch);
        else
            fputc(ch, f);
    }
    fputc('"', f);
}

uint64_t vw__peak_rss(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
    return (uint64_t)ru.ru_maxrss * 1024u;
}

void vw__stats_local(vw_world *w)
{
    memset(w->wstats, 0, sizeof *w->wstats * (size_t)w->gworkers);
    uint64_t rss = vw__peak_rss();
    for (int i = 0; i < w->nworkers; i++) {
        const vw__worker *wk = &w->workers[i];
        vw__worker_stats *ws = &w->wstats[wk->global];
        ws->busy_s = wk->busy_s;
        ws->msgs_sent = wk->msgs_sent;
        ws->bytes_sent = wk->bytes_sent;
        ws->packets_sent = wk->packets_sent;
        ws->msgs_remote = wk->msgs_remote;
        ws->bytes_remote = wk->bytes_remote;
        ws->turns_remote = wk->turns_remote;
        ws->peak_rss = rss;
        ws->records = w->nslots;
        ws->fetched = w->fetched;
    }
}

static void write_body(vw_world *w, FILE *f, const char *command, const char *extra)
{
    char layout[64];
    vw_decomp_layout_string(w->decomp, layout, sizeof layout);
    fprintf(f, "{\n  \"command\": ");
    json_string(f, command ? command : "");
    fprintf(f, ",\n  \"version\": \"%s\",\n", VW_VERSION_STRING);
    fprintf(f, "  \"engine\": {\"kind\": \"%s\", \"processes\": %d, \"workers\": %d, \"workers_per_process\": %d},\n",
            w->nprocs > 1 ? "mpi" : "threads", w->nprocs, w->gworkers, w->nworkers);
    fprintf(f, "  \"decomposition\": {\"kind\": \"%s\", \"layout\": \"%s\", \"cells\": %d, \"max_neighbours\": %d, \"rotated\": %s},\n",
            vw_decomp_kind_name(vw_decomp_get_kind(w->decomp)), layout, w->ncells,
            vw_decomp_max_neighbours(w->decomp), vw_decomp_frame(w->decomp) ? "true" : "false");
    /* Every object; each process keeps the records of its share (workers[].records). */
    fprintf(f, "  \"objects\": %zu,\n", w->nobjects);
    double lambda = vw_world_imbalance(w);
    /* The strategy and the phases are named by the caller: escaped like every string. */
    fprintf(f, "  \"balance\": {\"strategy\": ");
    json_string(f, w->balance_strategy[0] ? w->balance_strategy : "none");
    fprintf(f, ", \"imbalance_before\": %.6g, \"imbalance_after\": %.6g, \"migrated_objects\": %llu, \"imbalance\": %.6g, \"efficiency\": %.6g},\n",
            num(w->balance_strategy[0] ? w->imbalance_before : lambda),
            num(w->balance_strategy[0] ? w->imbalance_after : lambda),
            (unsigned long long)w->migrated, num(lambda), num(lambda > 0 ? 1.0 / lambda : 0));
    fprintf(f, "  \"time_s\": {");
    double total = 0;
    for (int i = 0; i < w->nphases; i++) {
        json_string(f, w->phases[i].name);
        fprintf(f, ": %.6f, ", num(w->phases[i].s));
        if (strcmp(w->phases[i].name, "total") != 0) total += num(w->phases[i].s);
    }
    int has_total = 0;
    for (int i = 0; i < w->nphases; i++) has_total |= strcmp(w->phases[i].name, "total") == 0;
    if (!has_total)
        fprintf(f, "\"total\": %.6f", num(total));
    else
        fprintf(f, "\"phases\": %d", w->nphases);
    fprintf(f, "},\n");
    /* Whole-job figures: w->wstats holds every process's workers after a run. */
    uint64_t msgs = 0, bytes = 0, packets = 0, mr = 0, br = 0;
    for (int g = 0; g < w->gworkers; g++) {
        msgs += w->wstats[g].msgs_sent;
        bytes += w->wstats[g].bytes_sent;
        packets += w->wstats[g].packets_sent;
        mr += w->wstats[g].msgs_remote;
        br += w->wstats[g].bytes_remote;
    }
    fprintf(f, "  \"messages\": {\"count\": %llu, \"bytes\": %llu, \"packets\": %llu, \"remote_count\": %llu, \"remote_bytes\": %llu},\n",
            (unsigned long long)msgs, (unsigned long long)bytes, (unsigned long long)packets,
            (unsigned long long)mr, (unsigned long long)br);
    if (w->m->ncounters > 0) {
        fprintf(f, "  \"counters\": {");
        for (int k = 0; k < w->m->ncounters; k++) {
            fprintf(f, "%s", k ? ", " : "");
            json_string(f, w->m->counters[k]);
            fprintf(f, ": %lld", (long long)vw_world_counter(w, k));
        }
        fprintf(f, "},\n");
    }
    if (extra && *extra) fprintf(f, "  %s,\n", extra);
    fprintf(f, "  \"cells\": [\n");
    for (int c = 0; c < w->ncells; c++) {
        vw_box b = vw_decomp_cell_box(w->decomp, c);
        vw_cell_stats cs;
        vw_world_cell_stats(w, c, &cs);
        fprintf(f, "    {\"id\": %d, \"box\": [[%.9g,%.9g,%.9g],[%.9g,%.9g,%.9g]], \"worker\": %d, \"objects\": %zu, \"messages_in\": %llu, \"busy_s\": %.6f, \"load\": %.6g",
                c, num(b.lo[0]), num(b.lo[1]), num(b.lo[2]), num(b.hi[0]), num(b.hi[1]), num(b.hi[2]),
                cs.worker, cs.objects, (unsigned long long)cs.messages_in, num(cs.busy_s), num(cs.load));
        for (int k = 0; k < w->m->ncounters; k++) {
            fprintf(f, ", ");
            json_string(f, w->m->counters[k]);
            fprintf(f, ": %lld", (long long)vw_world_cell_counter(w, c, k));
        }
        /* A duplicated cell: the figures above are the sums over the master and its
           copies; each copy's worker and busy time follow. */
        const vw__cell *cl = &w->cells[c];
        if (cl->nreps) {
            fprintf(f, ", \"replicas\": [");
            for (int r = 0; r < cl->nreps; r++)
                fprintf(f, "%s{\"worker\": %d, \"busy_s\": %.6f, \"messages_in\": %llu}", r ? ", " : "",
                        cl->reps[r].worker, num(cl->reps[r].busy.s),
                        (unsigned long long)cl->reps[r].messages_in);
            fprintf(f, "], \"master_busy_s\": %.6f", num(cl->busy.s));
        }
        fprintf(f, "}%s\n", c + 1 < w->ncells ? "," : "");
    }
    fprintf(f, "  ],\n  \"workers\": [\n");
    uint64_t rss_here = vw__peak_rss();
    for (int g = 0; g < w->gworkers; g++) {
        const vw__worker_stats *ws = &w->wstats[g];
        uint64_t rss = vw__worker_process(w, g) == w->rank || !ws->peak_rss ? rss_here : ws->peak_rss;
        /* The worker's speed (vw_config.worker_speeds, 1 when none were given): with
           speeds lambda is the longest time against a split by speed, which a reader
           can recompute from busy_s only when the speeds are here. */
        fprintf(f, "    {\"id\": %d, \"process\": %d, \"speed\": %.9g, \"busy_s\": %.6f, \"peak_rss_bytes\": %llu, \"records\": %llu, \"records_fetched\": %llu, \"messages\": %llu, \"bytes\": %llu, \"remote_count\": %llu, \"remote_bytes\": %llu, \"remote_turns\": %llu",
                g, vw__worker_process(w, g), num(w->speeds ? w->speeds[g] : 1.0),
                num(vw_world_worker_busy(w, g)), (unsigned long long)rss,
                (unsigned long long)(vw__worker_process(w, g) == w->rank ? w->nslots : ws->records),
                (unsigned long long)(vw__worker_process(w, g) == w->rank ? w->fetched : ws->fetched),
                (unsigned long long)ws->msgs_sent, (unsigned long long)ws->bytes_sent,
                (unsigned long long)ws->msgs_remote, (unsigned long long)ws->bytes_remote,
                (unsigned long long)ws->turns_remote);
        /* The module's counters of the units (cells, copies) on this worker: what each
           worker made, e.g. a farmed cell's eye rays by copy. */
        if (w->m->ncounters > 0) {
            fprintf(f, ", \"counters\": {");
            for (int k = 0; k < w->m->ncounters; k++) {
                fprintf(f, "%s", k ? ", " : "");
                json_string(f, w->m->counters[k]);
                fprintf(f, ": %lld", (long long)vw_world_worker_counter(w, g, k));
            }
            fprintf(f, "}");
        }
        fprintf(f, "}%s\n", g + 1 < w->gworkers ? "," : "");
    }
    /* Per process: the sums of its workers (messages sent, and what left the process). */
    fprintf(f, "  ],\n  \"processes\": [\n");
    for (int p = 0; p < w->nprocs; p++) {
        double busy = 0;
        uint64_t pm = 0, pb = 0, prm = 0, prb = 0, rss = p == w->rank ? rss_here : 0;
        for (int g = p * w->nworkers; g < (p + 1) * w->nworkers; g++) {
            busy += vw_world_worker_busy(w, g);
            pm += w->wstats[g].msgs_sent;
            pb += w->wstats[g].bytes_sent;
            prm += w->wstats[g].msgs_remote;
            prb += w->wstats[g].bytes_remote;
            if (p != w->rank && w->wstats[g].peak_rss > rss) rss = w->wstats[g].peak_rss;
        }
        fprintf(f, "    {\"id\": %d, \"workers\": %d, \"busy_s\": %.6f, \"messages\": %llu, \"bytes\": %llu, \"remote_count\": %llu, \"remote_bytes\": %llu, \"peak_rss_bytes\": %llu}%s\n",
                p, w->nworkers, num(busy), (unsigned long long)pm, (unsigned long long)pb,
                (unsigned long long)prm, (unsigned long long)prb, (unsigned long long)rss,
                p + 1 < w->nprocs ? "," : "");
    }
    fprintf(f, "  ]\n}\n");
}

vw_status vw_world_write_stats(vw_world *w, const char *path, const char *command,
                               const char *extra_json)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    if (!path) return vw__world_error(w, VW_E_INVAL, "vw_world_write_stats: path is NULL");
    if (w->rank != 0) return VW_OK;
    char err[512];
    vw_outfile *of;
    vw_status st = vw_outfile_open(path, &of, err, sizeof err);
    if (st == VW_OK) {
        write_body(w, vw_outfile_stream(of), command, extra_json);
        st = vw_outfile_commit(of, err, sizeof err);
    }
    if (st != VW_OK) return vw__world_error(w, st, "%s", err);
    return VW_OK;
}
