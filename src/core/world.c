/* world.c - the world: cells, their objects and their workers; creation, placement of
 * objects into cells, commit, run, and re-decomposition between runs.
 *
 * Placement rule: an object belongs to every cell its bounds overlap, each cell box
 * widened by a tiny pad, so a ray hitting an object near a wall finds it in whichever
 * cell owns that stretch of the ray.
 */
#include "core/hash.h"
#include "core/world_internal.h"
#include "vwalls/engine.h"

#include <limits.h>
#include <link.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static void set_error(vw_world *w, vw_status st, const char *fmt, va_list ap)
{
    vsnprintf(w->errmsg, sizeof w->errmsg, fmt, ap);
    w->err = st;
}

vw_status vw__world_error(vw_world *w, vw_status st, const char *fmt, ...)
{
    if (w->err == VW_OK) {
        va_list ap;
        va_start(ap, fmt);
        set_error(w, st, fmt, ap);
        va_end(ap);
    }
    return st;
}

/* Why this thread's last vw_world_create failed: there is no world to hold it, so
   vw_world_errmsg(NULL) returns it (sqlite3_errmsg(NULL) style). */
static _Thread_local char create_err[512];

static vw_status create_failed(vw_status st, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static vw_status create_failed(vw_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(create_err, sizeof create_err, fmt, ap);
    va_end(ap);
    return st;
}

const char *vw_world_errmsg(const vw_world *w)
{
    if (!w) return create_err[0] ? create_err : "no world";
    return w->err == VW_OK ? "no error" : w->errmsg;
}

/* Under MPI, every process takes the steps of a world's life alike (create, add objects,
   update an object, set copies, redecompose or remap, commit, run), and the next one
   after each is collective somewhere. A step that fails on one process only (out of
   memory, a bad argument given to that process) and succeeds on the others would send
   that process away (to vw_world_free, MPI_Finalize) while the others wait for it in
   their next collective call, for ever. So each step ends in agreement: every process
   returns the status of the lowest failing one, and holds "rank R: its message" as the
   world's error (that process too). One MPI_Allreduce of an int when all is well.
   `step` names the step where the failure left no message of its own. */
vw_status vw__world_step_agreed(vw_world *w, vw_status st, const char *step)
{
    char msg[512] = "";
    if (st != VW_OK && w->err == VW_OK) vw__world_error(w, st, "%s: %s", step, vw_status_message(st));
    if (st != VW_OK) snprintf(msg, sizeof msg, "%s", w->errmsg);
    if (!w->transport) return st;
    vw_status all = vw__world_agree(w, st, msg, sizeof msg);
    if (all != VW_OK) {
        w->err = VW_OK; /* this step's own message gives way to the agreed one */
        vw__world_error(w, all, "%s", msg);
    }
    return all;
}

static uint64_t env_u64(const char *name)
{
    const char *s = getenv(name);
    if (!s || !*s) return 0;
    return strtoull(s, NULL, 0);
}

void vw_config_init(vw_config *c)
{
    memset(c, 0, sizeof *c);
    c->workers = 0;
    c->packet_bytes = 32 * 1024;
    c->cap_bytes = 64u * 1024 * 1024;
    c->steal = -1;
    c->stress_seed = env_u64("VW_STRESS");
    c->stress_split = env_u64("VW_STRESS_SPLIT") != 0;
}

int vw__worker_process(const vw_world *w, int global_worker) { return global_worker / w->nworkers; }

/* The worker of this process hosting unit r of cell c (0: the master, r: copy r), or
   NULL when another process hosts it. */
static vw__worker *unit_worker(vw_world *w, int c, int r)
{
    int g = r ? w->cells[c].reps[r - 1].worker : w->cell_worker[c];
    return vw__worker_process(w, g) == w->rank ? &w->workers[g - w->rank * w->nworkers] : NULL;
}

/* The per-worker lists of what each worker of this process hosts: the cells it is the
   master of, then the copies of duplicated cells (cell_rep says which). Two passes over
   the units, counting then filling, so each list is the size of its worker's share:
   O(cells + units) time and memory, whatever the number of workers. */
static vw_status assign_units(vw_world *w)
{
    w->units_stale = 1; /* until every list is whole */
    for (int i = 0; i < w->nworkers; i++) w->workers[i].ncells = 0;
    for (int c = 0; c < w->ncells; c++)
        for (int r = 0; r <= w->cells[c].nreps; r++) {
            vw__worker *wk = unit_worker(w, c, r);
            if (wk) wk->ncells++;
        }
    for (int i = 0; i < w->nworkers; i++) {
        vw__worker *wk = &w->workers[i];
        size_t n = (size_t)wk->ncells;
        wk->ncells = 0;
        wk->step_cursor = 0;
        free(wk->cells);
        free(wk->cell_rep);
        wk->cells = malloc(sizeof(int) * (n ? n : 1));
        wk->cell_rep = malloc(sizeof(int) * (n ? n : 1));
        if (!wk->cells || !wk->cell_rep) return VW_E_NOMEM;
    }
    for (int c = 0; c < w->ncells; c++)
        for (int r = 0; r <= w->cells[c].nreps; r++) {
            vw__worker *wk = unit_worker(w, c, r);
            if (!wk) continue;
            wk->cells[wk->ncells] = c;
            wk->cell_rep[wk->ncells++] = r;
        }
    w->units_stale = 0;
    return VW_OK;
}

void *vw__calloc_lines(size_t n, size_t size)
{
    if (size && n > (SIZE_MAX - VW__LINE) / size) return NULL;
    size_t bytes = (n * size + VW__LINE - 1) / VW__LINE * VW__LINE;
    if (!bytes) bytes = VW__LINE;
    void *p = aligned_alloc(VW__LINE, bytes);
    if (p) memset(p, 0, bytes);
    return p;
}

/* Sets up cells -> workers and the per-worker cell lists for the current mapping. */
static vw_status map_cells(vw_world *w, const int *cell_worker)
{
    for (int c = 0; c < w->ncells; c++) {
        int g = cell_worker ? cell_worker[c] : (int)((long)c * w->gworkers / w->ncells);
        if (g < 0 || g >= w->gworkers)
            return vw__world_error(w, VW_E_INVAL, "mapping sends cell %d to worker %d of %d", c, g,
                                   w->gworkers);
        w->cell_worker[c] = g;
        w->cells[c].worker = g;
    }
    return assign_units(w);
}

static vw_status alloc_cells(vw_world *w)
{
    w->ncells = vw_decomp_cell_count(w->decomp);
    w->cells = vw__calloc_lines((size_t)w->ncells, sizeof *w->cells);
    w->cell_worker = calloc((size_t)w->ncells, sizeof(int));
    if (!w->cells || !w->cell_worker) return VW_E_NOMEM;
    int nc = w->m->ncounters > 0 ? w->m->ncounters : 1;
    for (int c = 0; c < w->ncells; c++) {
        w->cells[c].counters = vw__calloc_lines((size_t)nc, sizeof(int64_t));
        if (!w->cells[c].counters) return VW_E_NOMEM;
    }
    vw_box wb = vw_decomp_world(w->decomp);
    double ext = 0;
    for (int a = 0; a < 3; a++)
        if (wb.hi[a] - wb.lo[a] > ext) ext = wb.hi[a] - wb.lo[a];
    w->pad = ext * 1e-9;
    return VW_OK;
}

static void free_replica(vw_world *w, vw__replica *r)
{
    if (r->built && w->m->cell_free) w->m->cell_free(r->state, w->user);
    free(r->counters);
}

static void free_cells(vw_world *w)
{
    if (!w->cells) return;
    for (int c = 0; c < w->ncells; c++) {
        vw__cell *cl = &w->cells[c];
        if (cl->built && w->m->cell_free) w->m->cell_free(cl->state, w->user);
        for (int r = 0; r < cl->nreps; r++) free_replica(w, &cl->reps[r]);
        free(cl->reps);
        free(cl->rr);
        free(cl->share_seq);
        free(cl->objs);
        free(cl->counters);
    }
    free(w->cells);
    free(w->cell_worker);
    w->cells = NULL;
    w->cell_worker = NULL;
}

/* cfg.worker_slowdown, one per global worker, into the world's own copy: the workers
   read it at every switch of cell, long after the caller's array may have gone. */
static vw_status copy_slowdown(vw_world *w)
{
    const double *s = w->cfg.worker_slowdown;
    w->cfg.worker_slowdown = NULL;
    if (!s) return VW_OK;
    w->slowdown = malloc(sizeof(double) * (size_t)w->gworkers);
    if (!w->slowdown) return VW_E_NOMEM;
    memcpy(w->slowdown, s, sizeof(double) * (size_t)w->gworkers);
    w->cfg.worker_slowdown = w->slowdown;
    return VW_OK;
}

/* cfg.worker_speeds, one per global worker, into the world's own copy. */
static vw_status copy_speeds(vw_world *w)
{
    const double *s = w->cfg.worker_speeds;
    w->cfg.worker_speeds = NULL; /* the caller's array may go; w->speeds stays */
    if (!s) return VW_OK;
    for (int g = 0; g < w->gworkers; g++)
        if (!(s[g] > 0) || !isfinite(s[g]))
            return vw__world_error(w, VW_E_INVAL, "worker %d has speed %g: speeds must be "
                                   "positive and finite", g, s[g]);
    w->speeds = malloc(sizeof(double) * (size_t)w->gworkers);
    if (!w->speeds) return VW_E_NOMEM;
    memcpy(w->speeds, s, sizeof(double) * (size_t)w->gworkers);
    return VW_OK;
}

/* The module's shape as it reaches the wire, part by part (MODULE_PARTS numbers),
   compared between processes when a world is created, so that a mismatch can say what
   differs: the library's ABI and message header, the name, the record size, the
   counts of kinds and counters, the counters' names, each kind's size (+ 1; 0: no such
   kind) and each kind's name, flags and handlers present (hashed). */
enum { PART_LIBRARY, PART_NAME, PART_OBJECT, PART_NKINDS, PART_NCOUNTERS, PART_COUNTERS,
       PART_KIND_SIZE, PART_KIND = PART_KIND_SIZE + VW_MAX_KINDS,
       MODULE_PARTS = PART_KIND + VW_MAX_KINDS };

static void module_parts(const vw_module *m, uint64_t part[MODULE_PARTS])
{
    memset(part, 0, sizeof(uint64_t) * MODULE_PARTS);
    part[PART_LIBRARY] = ((uint64_t)m->abi << 32) | sizeof(vw__msg_header);
    part[PART_NAME] = vw__fnv1a(VW__FNV_OFFSET, m->name, strlen(m->name) + 1);
    part[PART_OBJECT] = m->object_size;
    part[PART_NKINDS] = (uint64_t)m->nkinds;
    part[PART_NCOUNTERS] = (uint64_t)m->ncounters;
    uint64_t h = VW__FNV_OFFSET;
    for (int c = 0; c < m->ncounters; c++) h = vw__fnv1a(h, m->counters[c], strlen(m->counters[c]) + 1);
    part[PART_COUNTERS] = h;
    for (int k = 0; k < m->nkinds; k++) {
        const vw_msg_kind *K = &m->kinds[k];
        uint64_t v[3] = {K->flags, K->handle != NULL, K->output != NULL};
        part[PART_KIND_SIZE + k] = K->size + 1;
        part[PART_KIND + k] = vw__fnv1a(vw__fnv1a(VW__FNV_OFFSET, v, sizeof v), K->name, strlen(K->name) + 1);
    }
}

/* What part p of the module's shape is on process r (theirs) and on process 0 (first),
   said for the message of a mismatch. */
static void module_part_differs(const vw_module *m, int p, int r, uint64_t theirs, uint64_t first,
                                char *buf, size_t len)
{
    unsigned long long t = theirs, f = first;
    int k = p >= PART_KIND ? p - PART_KIND : p - PART_KIND_SIZE;
    const char *kname = p >= PART_KIND_SIZE && k < m->nkinds ? m->kinds[k].name : "?";
    if (p == PART_LIBRARY)
        snprintf(buf, len, "another vwalls library (its module ABI or message header)");
    else if (p == PART_NAME)
        snprintf(buf, len, "another module name");
    else if (p == PART_OBJECT)
        snprintf(buf, len, "objects of %llu bytes on process %d, %llu on process 0", t, r, f);
    else if (p == PART_NKINDS)
        snprintf(buf, len, "%llu message kinds on process %d, %llu on process 0", t, r, f);
    else if (p == PART_NCOUNTERS)
        snprintf(buf, len, "%llu counters on process %d, %llu on process 0", t, r, f);
    else if (p == PART_COUNTERS)
        snprintf(buf, len, "other counter names");
    else if (p < PART_KIND)
        snprintf(buf, len, "message kind %d ('%s') of %llu bytes on process %d, %llu on process 0",
                 k, kname, t - 1, r, f - 1);
    else
        snprintf(buf, len, "message kind %d ('%s') with another name, flags or handlers", k, kname);
}

/* The running program's GNU build ID (the linker's hash of the executable), hashed; 0
   when it has none. Two processes with the same ID run the same machine code, so their
   messages' records have the same layout, which module_fingerprint cannot see inside. */
static int build_id_note(struct dl_phdr_info *info, size_t size, void *user)
{
    (void)size;
    uint64_t *h = user;
    for (int i = 0; i < info->dlpi_phnum; i++) {
        const ElfW(Phdr) *ph = &info->dlpi_phdr[i];
        if (ph->p_type != PT_NOTE) continue;
        const char *p = (const char *)(info->dlpi_addr + ph->p_vaddr), *end = p + ph->p_memsz;
        while (p + sizeof(ElfW(Nhdr)) <= end) {
            const ElfW(Nhdr) *n = (const ElfW(Nhdr) *)p;
            const char *name = p + sizeof *n;
            const char *desc = name + ((n->n_namesz + 3) & ~3u);
            if (desc + n->n_descsz > end) break;
            if (n->n_type == NT_GNU_BUILD_ID && n->n_namesz == 4 && !memcmp(name, "GNU", 4)) {
                *h = vw__fnv1a(VW__FNV_OFFSET, desc, n->n_descsz);
                return 1;
            }
            p = desc + ((n->n_descsz + 3) & ~3u);
        }
    }
    return 1; /* the first object is the program itself: stop there */
}

static uint64_t program_build_id(void)
{
    uint64_t h = 0;
    dl_iterate_phdr(build_id_note, &h);
    return h;
}

vw_status vw_world_create(const vw_module *m, void *user, const vw_decomp *d, const vw_config *c,
                          vw_world **out)
{
    create_err[0] = 0;
    if (!out) return create_failed(VW_E_INVAL, "vw_world_create: out is NULL");
    *out = NULL;
    if (!m || !d) return create_failed(VW_E_INVAL, "vw_world_create: no %s", m ? "decomposition" : "module");
    if (m->abi != VW_MODULE_ABI)
        return create_failed(VW_E_INVAL, "module '%s': abi %d, the library's is %d (set .abi = "
                             "VW_MODULE_ABI and rebuild)", m->name ? m->name : "?", m->abi, VW_MODULE_ABI);
    /* Every message about the module names it (runtime.c's misuse: a NULL for %s). */
    if (!m->name || !m->name[0])
        return create_failed(VW_E_INVAL, "vw_world_create: the module has no name (vw_module.name)");
    if (m->nkinds < 0 || m->nkinds > VW_MAX_KINDS || m->ncounters < 0 || m->ncounters > VW_MAX_COUNTERS)
        return create_failed(VW_E_INVAL, "module '%s': %d message kinds and %d counters (at most %d "
                             "and %d)", m->name ? m->name : "?", m->nkinds, m->ncounters, VW_MAX_KINDS,
                             VW_MAX_COUNTERS);
    /* The tables the counts promise: read at every send and in the stats JSON. */
    if ((m->nkinds > 0 && !m->kinds) || (m->ncounters > 0 && !m->counters))
        return create_failed(VW_E_INVAL, "module '%s': %d message kinds and %d counters, but no "
                             "table of %s", m->name ? m->name : "?", m->nkinds, m->ncounters,
                             m->nkinds > 0 && !m->kinds ? "kinds" : "counter names");
    for (int k = 0; k < m->ncounters; k++)
        if (!m->counters[k])
            return create_failed(VW_E_INVAL, "module '%s': counter %d has no name",
                                 m->name ? m->name : "?", k);
    if (m->object_size && !m->object_bounds)
        return create_failed(VW_E_INVAL, "module '%s': objects without object_bounds",
                             m->name ? m->name : "?");
    for (int k = 0; k < m->nkinds; k++) {
        const vw_msg_kind *K = &m->kinds[k];
        if (K->size > VW_MAX_MSG_BYTES)
            return create_failed(VW_E_INVAL, "module '%s': message kind %d is %zu bytes (at most %d)",
                                 m->name, k, K->size, (int)VW_MAX_MSG_BYTES);
        /* A kind an initialiser left out (nkinds larger than the table's entries, or a
           designated initialiser that skipped an index) is all zeros: it was accepted,
           and its first send stopped the process ("the kind has no handle"). */
        if (!K->name || !K->name[0])
            return create_failed(VW_E_INVAL, "module '%s': message kind %d has no name (missing "
                                 "from the kinds table? nkinds is %d)", m->name, k, m->nkinds);
        if (!K->handle && !K->output)
            return create_failed(VW_E_INVAL, "module '%s': message kind %d ('%s') has neither a "
                                 "handle (sent to cells) nor an output (sent to the output)",
                                 m->name, k, K->name);
        if (K->flags & ~VW_MSG_INDEPENDENT)
            return create_failed(VW_E_INVAL, "module '%s': message kind %d ('%s') has unknown "
                                 "flags 0x%x (VW_MSG_INDEPENDENT is the only one)", m->name, k,
                                 K->name, K->flags & ~VW_MSG_INDEPENDENT);
    }
    vw_world *w = calloc(1, sizeof *w);
    if (!w) return create_failed(VW_E_NOMEM, "vw_world_create: out of memory");
    w->m = m;
    w->user = user;
    if (c)
        w->cfg = *c;
    else
        vw_config_init(&w->cfg);
    if (w->cfg.packet_bytes < 64) w->cfg.packet_bytes = 64;
    w->rank = 0;
    w->nprocs = 1;
    /* The cores this process may run on: the default worker count, and whether the
       workers leave a core to spare (steal, share_core below). */
    int cores = vw_host_cores();
    if (w->cfg.workers < 0) {
        create_failed(VW_E_INVAL, "vw_world_create: %d workers (0 = one per core)", w->cfg.workers);
        free(w);
        return VW_E_INVAL;
    }
    w->nworkers = w->cfg.workers > 0 ? w->cfg.workers : cores;
    if (w->nworkers > VW__MAX_WORKERS) {
        create_failed(VW_E_LIMIT, "vw_world_create: %d workers (at most %d)", w->nworkers,
                      VW__MAX_WORKERS);
        free(w);
        return VW_E_LIMIT;
    }
    /* A packet is one allocation of its header plus packet_bytes, and one MPI message
       counted in an int: near SIZE_MAX the allocation's size wrapped to a few bytes. */
    if (w->cfg.packet_bytes > VW__MAX_PACKET_BYTES) {
        create_failed(VW_E_LIMIT, "vw_world_create: packets of %zu bytes (at most %zu)",
                      w->cfg.packet_bytes, (size_t)VW__MAX_PACKET_BYTES);
        free(w);
        return VW_E_LIMIT;
    }
    w->steal = w->cfg.steal > 0 || (w->cfg.steal < 0 && w->nworkers <= cores);
    w->cfg.cell_worker = NULL; /* copied into w->cell_worker below */
    pthread_mutex_init(&w->output_mu, NULL);
    pthread_mutex_init(&w->pool_mu, NULL);
    pthread_cond_init(&w->pool_cv, NULL);
    /* Under MPI: rank, nprocs and the transport. Every process must pass the same
       worker count (checked by the transport here), decomposition and mapping (checked
       at every commit: world_fingerprint). */
    vw_status st = vw__mpi_attach(w);
    /* Packets cross MPI as raw bytes, read by the receiver's module: processes running
       other builds (another message kind, another record size) would read each other's
       messages wrongly without a word. (Attached on every process or on none.) */
    if (st == VW_OK && w->transport) {
        uint64_t part[MODULE_PARTS], theirs = 0, first = 0;
        module_parts(w->m, part);
        int p = 0, r = vw__mpi_first_differing_n(w, part, MODULE_PARTS, &p, &theirs, &first);
        if (r >= 0) {
            char what[256];
            module_part_differs(w->m, p, r, theirs, first, what, sizeof what);
            st = vw__world_error(w, VW_E_INVAL, "process %d runs another module than process 0 "
                                 "(module '%s': %s): every process must run the same build", r,
                                 w->m->name, what);
        }
    }
    /* The same module by its shape can still lay out a record's bytes otherwise (another
       version of the sources, another compiler): the programs' build IDs tell. A test
       plays another build with VW_FAULT=build-id (each process's own ID); VW_MIXED_BUILDS=1
       lets builds known to agree (rebuilt with other flags, say) run together. */
    if (st == VW_OK && w->transport) {
        uint64_t id = program_build_id();
        if (vw_test_fault("build-id")) id ^= (uint64_t)w->rank + 1;
        int r = vw__mpi_first_differing(w, id);
        const char *mixed = getenv("VW_MIXED_BUILDS");
        if (r >= 0 && !(mixed && !strcmp(mixed, "1")))
            st = vw__world_error(w, VW_E_INVAL, "process %d runs another build of this program than "
                                 "process 0 (their GNU build IDs differ): messages cross as raw bytes, "
                                 "so every process must run the same build (the same sources, built "
                                 "the same way); VW_MIXED_BUILDS=1 runs them anyway", r);
    }
    w->gworkers = w->nworkers * w->nprocs;
    w->share_core = w->transport && w->nworkers >= cores;
    if (st == VW_OK) {
        w->wstats = calloc((size_t)w->gworkers, sizeof *w->wstats);
        if (!w->wstats) st = VW_E_NOMEM;
    }
    if (st == VW_OK) st = vw_decomp_clone(d, &w->decomp);
    if (st == VW_OK) st = alloc_cells(w);
    if (st == VW_OK) {
        w->workers = vw__calloc_lines((size_t)w->nworkers, sizeof *w->workers);
        if (!w->workers) st = VW_E_NOMEM;
    }
    for (int i = 0; st == VW_OK && i < w->nworkers; i++) {
        vw__worker *wk = &w->workers[i];
        wk->w = w;
        wk->local = i;
        wk->global = w->rank * w->nworkers + i;
        pthread_mutex_init(&wk->mu, NULL);
        pthread_cond_init(&wk->cv, NULL);
        atomic_init(&wk->outstanding, 0);
        wk->rng = w->cfg.stress_seed * 0x2545f4914f6cdd1dull + (uint64_t)wk->global + 1;
        wk->out = vw__calloc_lines((size_t)w->gworkers + 1, sizeof *wk->out);
        wk->tr_proc = vw__calloc_lines(2 * (size_t)w->nprocs, sizeof *wk->tr_proc);
        if (!wk->out || !wk->tr_proc) st = VW_E_NOMEM;
    }
    if (st == VW_OK) st = copy_speeds(w);
    if (st == VW_OK) st = copy_slowdown(w);
    if (st == VW_OK) st = map_cells(w, c ? c->cell_worker : NULL);
    /* Every process made the transport (vw__mpi_attach agrees on that); what failed
       after it may have failed on some processes only. */
    if (w->transport) st = vw__world_step_agreed(w, st, "vw_world_create");
    if (st != VW_OK) {
        create_failed(st, "%s", w->err != VW_OK ? w->errmsg : vw_status_message(st));
        vw_world_free(w);
        return st;
    }
    *out = w;
    return VW_OK;
}

void vw_world_free(vw_world *w)
{
    if (!w) return;
    vw__world_guard(w, "vw_world_free"); /* it would join the thread it runs on */
    vw__runtime_stop(w);
    if (w->transport) w->transport->free(w);
    free(w->wstats);
    free(w->speeds);
    free(w->slowdown);
    free_cells(w);
    if (w->workers) {
        for (int i = 0; i < w->nworkers; i++) {
            vw__worker *wk = &w->workers[i];
            if (wk->out)
                for (int d = 0; d <= w->gworkers; d++) free(wk->out[d]);
            free(wk->out);
            free(wk->tr_proc);
            free(wk->cells);
            free(wk->cell_rep);
            while (wk->head) {
                vw__packet *p = wk->head;
                wk->head = p->next;
                free(p);
            }
            pthread_mutex_destroy(&wk->mu);
            pthread_cond_destroy(&wk->cv);
        }
        free(w->workers);
    }
    while (w->posted) {
        vw__packet *p = w->posted;
        w->posted = p->next;
        free(p);
    }
    pthread_mutex_destroy(&w->output_mu);
    pthread_mutex_destroy(&w->pool_mu);
    pthread_cond_destroy(&w->pool_cv);
    vw_decomp_free(w->decomp);
    free(w->objects);
    free(w->slot);
    free(w->bounds);
    for (int i = 0; i < w->nphases; i++) free(w->phases[i].name);
    free(w->phases);
    free(w);
}

/* ---- objects ------------------------------------------------------------------------ */

static vw_status cell_add_object(vw__cell *c, size_t id)
{
    if (c->nobjs == c->capobjs) {
        size_t cap = c->capobjs ? 2 * c->capobjs : 16;
        size_t *o = realloc(c->objs, cap * sizeof *o);
        if (!o) return VW_E_NOMEM;
        c->objs = o;
        c->capobjs = cap;
    }
    c->objs[c->nobjs++] = id;
    return VW_OK;
}

/* Object id's bounds: kept for every object under MPI (a process need not keep its
   record), else read from its record. */
static void object_box(const vw_world *w, size_t id, vw_box *b)
{
    if (w->bounds)
        *b = w->bounds[id];
    else
        w->m->object_bounds(w->objects + id * w->m->object_size, b, w->user);
}

/* The cells object id overlaps; returns the count, list in *out (caller frees). */
static int object_cells(vw_world *w, size_t id, int **out)
{
    vw_box b;
    object_box(w, id, &b);
    int n = vw_decomp_cells_overlapping(w->decomp, &b, w->pad, NULL, 0);
    *out = malloc(sizeof(int) * (size_t)(n ? n : 1));
    if (!*out) return -1;
    vw_decomp_cells_overlapping(w->decomp, &b, w->pad, *out, n);
    return n;
}

/* ---- the records this process keeps (vw_world.objects) -------------------------------- */

/* Whether this process hosts cell c or one of its copies: then it builds it, from the
   records of the cell's objects. */
static int cell_here(const vw_world *w, int c)
{
    const vw__cell *cl = &w->cells[c];
    if (vw__worker_process(w, cl->worker) == w->rank) return 1;
    for (int r = 0; r < cl->nreps; r++)
        if (vw__worker_process(w, cl->reps[r].worker) == w->rank) return 1;
    return 0;
}

/* The process that keeps the record of an object no cell holds (so that every record
   is kept somewhere: a later decomposition or update may place it again). */
static int home_of(const vw_world *w, size_t id) { return (int)(id % (size_t)w->nprocs); }

/* Whether a process keeps the record of object id, held by cells[0..n): it builds one
   of them, or none holds it and this is its home. */
static int record_kept_here(const vw_world *w, size_t id, const int *cells, int n)
{
    if (n == 0) return home_of(w, id) == w->rank;
    for (int i = 0; i < n; i++)
        if (cell_here(w, cells[i])) return 1;
    return 0;
}

/* Room for `more` records past the nslots kept (doubling); 0 if out of memory. */
static int reserve_slots(vw_world *w, size_t more)
{
    size_t osz = w->m->object_size;
    if (more > SIZE_MAX / osz - w->nslots) return 0;
    if (w->nslots + more <= w->capslots) return 1;
    size_t cap = w->capslots ? w->capslots : 64;
    while (cap < w->nslots + more) cap = cap > SIZE_MAX / osz / 2 ? w->nslots + more : 2 * cap;
    unsigned char *o = realloc(w->objects, cap * osz);
    if (!o) return 0;
    w->objects = o;
    w->capslots = cap;
    return 1;
}

/* Under MPI: the record of object id given (add, update), held by cells[0..n), kept
   when this process keeps it (record_kept_here), else forgotten. */
static vw_status keep_record(vw_world *w, size_t id, const void *record, const int *cells, int n)
{
    size_t osz = w->m->object_size;
    if (!record_kept_here(w, id, cells, n)) {
        w->slot[id] = VW__NO_SLOT; /* a record kept before is dropped at the next commit */
        return VW_OK;
    }
    if (w->slot[id] == VW__NO_SLOT) {
        if (!reserve_slots(w, 1)) return VW_E_NOMEM;
        w->slot[id] = w->nslots++;
    }
    memcpy(w->objects + w->slot[id] * osz, record, osz);
    return VW_OK;
}

/* At the commit, under MPI: the records this process's cells and copies now hold (a new
   decomposition, mapping or copies may have given it cells whose records it did not
   keep) are fetched from processes that keep them, then those it no longer needs are
   dropped: only after every process has what it needs, so no record is ever lost. The
   records kept are laid out by id, so a cell holding a run of objects builds from them
   in place (runtime.c). Collective; st is this process's status so far; every failure
   is agreed (msg says why), and a failed share leaves every process's records as they
   were. */
static vw_status share_records(vw_world *w, vw_status st, char *msg, size_t len)
{
    size_t n = w->nobjects, osz = w->m->object_size;
    /* keep[id]: this process keeps record id from now on; held[id]: some cell holds it */
    unsigned char *keep = calloc(n ? n : 1, 1), *held = calloc(n ? n : 1, 1);
    uint64_t *ask = NULL;
    unsigned char *store = NULL;
    size_t nkeep = 0, nask = 0;
    if (st == VW_OK && !(keep && held)) {
        st = VW_E_NOMEM;
        snprintf(msg, len, "out of memory fetching object records");
    }
    if (st == VW_OK && osz > INT_MAX) { /* (an MPI count of bytes) */
        st = VW_E_LIMIT;
        snprintf(msg, len, "object records of %zu bytes cannot cross MPI (at most %d)", osz, INT_MAX);
    }
    if (st == VW_OK) {
        for (int c = 0; c < w->ncells; c++) {
            int here = cell_here(w, c);
            for (size_t k = 0; k < w->cells[c].nobjs; k++) {
                held[w->cells[c].objs[k]] = 1;
                if (here) keep[w->cells[c].objs[k]] = 1;
            }
        }
        for (size_t id = 0; id < n; id++) {
            if (!held[id] && home_of(w, id) == w->rank) keep[id] = 1;
            nkeep += keep[id];
            nask += keep[id] && w->slot[id] == VW__NO_SLOT;
        }
        ask = malloc(sizeof *ask * (nask ? nask : 1));
        store = malloc(osz * (nkeep ? nkeep : 1));
        if (!ask || !store) {
            st = VW_E_NOMEM;
            snprintf(msg, len, "out of memory keeping %zu object records", nkeep);
        }
    }
    for (size_t id = 0, k = 0; st == VW_OK && id < n; id++)
        if (keep[id] && w->slot[id] == VW__NO_SLOT) ask[k++] = id;
    unsigned char *got = NULL;
    st = vw__mpi_fetch_records(w, st, ask, nask, &got, msg, len);
    if (st == VW_OK) {
        /* Nothing can fail from here: every process now has what it keeps. */
        size_t s = 0, k = 0;
        for (size_t id = 0; id < n; id++) {
            if (!keep[id]) {
                w->slot[id] = VW__NO_SLOT;
                continue;
            }
            const unsigned char *src =
                w->slot[id] != VW__NO_SLOT ? w->objects + w->slot[id] * osz : got + osz * k++;
            memcpy(store + s * osz, src, osz);
            w->slot[id] = s++;
        }
        free(w->objects);
        w->objects = store;
        w->nslots = w->capslots = nkeep;
        w->fetched += nask;
        store = NULL;
    }
    free(got);
    free(store);
    free(ask);
    free(held);
    free(keep);
    return st;
}

static vw_status place_object(vw_world *w, size_t id)
{
    int *cells;
    int n = object_cells(w, id, &cells);
    if (n < 0) return VW_E_NOMEM;
    vw_status st = VW_OK;
    for (int i = 0; i < n && st == VW_OK; i++) {
        st = cell_add_object(&w->cells[cells[i]], id);
        w->cells[cells[i]].dirty = 1;
        w->cells[cells[i]].version++; /* its copies rebuild too */
    }
    free(cells);
    return st;
}

/* Under MPI: object id's record given (add, update): its bounds kept, the record kept
   or not (keep_record), and the object placed. */
static vw_status place_record(vw_world *w, size_t id, const void *record)
{
    w->m->object_bounds(record, &w->bounds[id], w->user);
    int *cells;
    int n = object_cells(w, id, &cells);
    if (n < 0) return VW_E_NOMEM;
    vw_status st = keep_record(w, id, record, cells, n);
    free(cells);
    return st == VW_OK ? place_object(w, id) : st;
}

static vw_status add_objects(vw_world *w, const void *objects, size_t n)
{
    if (n && !objects)
        return vw__world_error(w, VW_E_INVAL, "vw_world_add_objects: %zu objects at NULL", n);
    size_t osz = w->m->object_size;
    if (!osz && n)
        return vw__world_error(w, VW_E_INVAL, "vw_world_add_objects: module '%s' has no objects "
                               "(object_size 0)", w->m->name);
    if (!osz) return VW_OK;
    if (n == 0) return VW_OK; /* also keeps memcpy away from a NULL buffer */
    /* The records' bytes must fit a size_t: a count near SIZE_MAX wrapped the capacity
       to a small allocation and the copy ran past it. */
    if (n > SIZE_MAX / osz - w->nobjects) return VW_E_NOMEM;
    size_t first = w->nobjects;
    if (w->nprocs > 1) {
        /* Every object's bounds and slot; its record only where it is kept. */
        size_t total = first + n;
        if (total > SIZE_MAX / sizeof(vw_box)) return VW_E_NOMEM;
        vw_box *b = realloc(w->bounds, total * sizeof *b);
        if (b) w->bounds = b;
        size_t *sl = b ? realloc(w->slot, total * sizeof *sl) : NULL;
        if (sl) w->slot = sl;
        if (!b || !sl) return VW_E_NOMEM;
        for (size_t i = first; i < total; i++) w->slot[i] = VW__NO_SLOT;
        w->nobjects = total;
        const unsigned char *rec = objects;
        for (size_t i = 0; i < n; i++) {
            vw_status st = place_record(w, first + i, rec + i * osz);
            if (st != VW_OK) return st;
        }
        w->committed = 0;
        return VW_OK;
    }
    if (!reserve_slots(w, n)) return VW_E_NOMEM;
    memcpy(w->objects + w->nobjects * osz, objects, n * osz);
    w->nobjects += n;
    w->nslots = w->nobjects;
    for (size_t i = first; i < w->nobjects; i++) {
        vw_status st = place_object(w, i);
        if (st != VW_OK) return st;
    }
    w->committed = 0;
    return VW_OK;
}

vw_status vw_world_add_objects(vw_world *w, const void *objects, size_t n)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    return vw__world_step_agreed(w, add_objects(w, objects, n), "vw_world_add_objects");
}

static vw_status update_object(vw_world *w, size_t id, const void *object)
{
    if (!object || id >= w->nobjects) return VW_E_INVAL;
    int *cells;
    int n = object_cells(w, id, &cells);
    if (n < 0) return VW_E_NOMEM;
    for (int i = 0; i < n; i++) {
        vw__cell *c = &w->cells[cells[i]];
        for (size_t k = 0; k < c->nobjs; k++)
            if (c->objs[k] == id) {
                memmove(&c->objs[k], &c->objs[k + 1], (c->nobjs - k - 1) * sizeof *c->objs);
                c->nobjs--;
                c->dirty = 1;
                c->version++;
                break;
            }
    }
    free(cells);
    vw_status st;
    if (w->slot) {
        st = place_record(w, id, object);
    } else {
        memcpy(w->objects + id * w->m->object_size, object, w->m->object_size);
        st = place_object(w, id);
    }
    w->committed = 0;
    return st;
}

vw_status vw_world_update_object(vw_world *w, size_t id, const void *object)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    return vw__world_step_agreed(w, update_object(w, id, object), "vw_world_update_object");
}

int vw_world_cells_of_object(const vw_world *w, size_t id, int *out, int max)
{
    if (!w || id >= w->nobjects) return 0;
    int n = 0;
    for (int c = 0; c < w->ncells; c++)
        for (size_t k = 0; k < w->cells[c].nobjs; k++)
            if (w->cells[c].objs[k] == id) {
                if (out && n < max) out[n] = c;
                n++;
                break;
            }
    return n;
}

/* What every process of a world must have been given alike, hashed: the walls (cell
   boxes and frame), the mapping, the copies of duplicated cells, the number of objects
   and their bounds. A process given another scene or layout would otherwise send its
   rays to cells the others do not expect, and show only as an abort on a malformed
   packet, or compute with other objects in its cells and give a wrong answer without a
   word (a scene file that differs between hosts). The bounds, not the records: a
   record's padding bytes may differ where its values do not. */
static uint64_t world_fingerprint(const vw_world *w)
{
    uint64_t h = VW__FNV_OFFSET;
    h = vw__fnv1a(h, &w->ncells, sizeof w->ncells);
    for (int c = 0; c < w->ncells; c++) {
        vw_box b = vw_decomp_cell_box(w->decomp, c);
        h = vw__fnv1a(h, &b, sizeof b);
        h = vw__fnv1a(h, &w->cell_worker[c], sizeof w->cell_worker[c]);
        const vw__cell *cl = &w->cells[c];
        h = vw__fnv1a(h, &cl->nreps, sizeof cl->nreps);
        for (int r = 0; r < cl->nreps; r++)
            h = vw__fnv1a(h, &cl->reps[r].worker, sizeof cl->reps[r].worker);
        /* The shares (worker speeds): processes that disagreed would make some batches
           twice and others never. */
        if (cl->share_len) h = vw__fnv1a(h, cl->share_seq, sizeof(int) * (size_t)cl->share_len);
    }
    const double *F = vw_decomp_frame(w->decomp);
    if (F) h = vw__fnv1a(h, F, 9 * sizeof *F);
    uint64_t n = w->nobjects;
    h = vw__fnv1a(h, &n, sizeof n);
    for (size_t i = 0; i < w->nobjects; i++) {
        vw_box b;
        object_box(w, i, &b);
        h = vw__fnv1a(h, &b, sizeof b);
    }
    return h;
}

vw_status vw_world_commit(vw_world *w)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    if (w->transport) {
        int r = vw__mpi_first_differing(w, world_fingerprint(w));
        if (r >= 0)
            return vw__world_error(w, VW_E_STATE,
                                   "process %d was given another world than process 0 (walls, "
                                   "mapping, copies, speeds, number of objects or their bounds "
                                   "differ): every process must run the same command on the same "
                                   "input", r);
    }
    int cell = -1, rep = 0;
    char msg[512] = "";
    /* The copies set since the last commit, listed per worker once for all of them. */
    vw_status st = w->units_stale ? assign_units(w) : VW_OK;
    if (st != VW_OK)
        snprintf(msg, sizeof msg, "listing each worker's cells and copies: %s",
                 vw_status_message(st));
    /* Under MPI the records of the cells to build come first: collective, and agreed
       (a failure before it too), so that msg says why on every process. Only when the
       world changed since it was last committed (every step that moves objects, cells
       or copies uncommits it, alike on every process): a commit of an unchanged world
       (an animation's every frame) need not scan the objects again. */
    if (w->nprocs > 1 && w->m->object_size && !w->committed) {
        st = share_records(w, st, msg, sizeof msg);
        if (st != VW_OK) return vw__world_error(w, st, "%s", msg);
    }
    if (st == VW_OK && (st = vw__runtime_build(w, &cell, &rep)) != VW_OK) {
        if (rep)
            snprintf(msg, sizeof msg, "building copy %d of cell %d failed: %s", rep, cell,
                     vw_status_message(st));
        else
            snprintf(msg, sizeof msg, "building cell %d failed: %s", cell, vw_status_message(st));
    }
    /* Under MPI every process builds only its own cells; they agree before anyone runs,
       so a cell that fails on one process fails the commit everywhere, naming the cell
       and (vw_world_agree's "rank R: ") the lowest failing process. */
    if (w->transport) st = vw__world_agree(w, st, msg, sizeof msg);
    if (st != VW_OK) return vw__world_error(w, st, "%s", msg);
    w->committed = 1;
    return VW_OK;
}

vw_status vw_world_post_sized(vw_world *w, int cell, int kind, const void *msg, size_t size)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w); /* (from a callback: stops the process, naming this call) */
    /* An unknown kind is left to vw_world_post to report. */
    if (kind >= 0 && kind < w->m->nkinds && w->m->kinds[kind].size != size)
        return vw__world_error(w, VW_E_INVAL, "posted a record of %zu bytes for message kind %d "
                               "('%s'), whose size is %zu bytes", size, kind,
                               w->m->kinds[kind].name, w->m->kinds[kind].size);
    return vw_world_post(w, cell, kind, msg);
}

vw_status vw_world_post(vw_world *w, int cell, int kind, const void *msg)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    if (cell < 0 || cell >= w->ncells)
        return vw__world_error(w, VW_E_INVAL, "posted to cell %d, which does not exist (%d cells)",
                               cell, w->ncells);
    if (kind < 0 || kind >= w->m->nkinds)
        return vw__world_error(w, VW_E_INVAL, "posted message kind %d, but module '%s' has %d kinds",
                               kind, w->m->name, w->m->nkinds);
    if (!msg && w->m->kinds[kind].size) /* a kind of size 0 has nothing to point to */
        return vw__world_error(w, VW_E_INVAL, "posted message kind %d of %zu bytes with no "
                               "message (NULL)", kind, w->m->kinds[kind].size);
    if (!w->m->kinds[kind].handle)
        return vw__world_error(w, VW_E_INVAL, "posted message kind %d ('%s') to cell %d, but the "
                               "kind has no handle (an output kind: sent with vw_send_output)",
                               kind, w->m->kinds[kind].name, cell);
    /* Every process keeps the message and the run gives it to the cell's worker then:
       a remap or a new decomposition may still move the cell (to another worker, or
       another process) before the run, and the worker chosen now received a message
       for a cell it no longer hosted (an abort, or a read past the cells). */
    int dest = w->cell_worker[cell];
    size_t size = w->m->kinds[kind].size;
    size_t stride = sizeof(vw__msg_header) + ((size + 7) & ~(size_t)7);
    vw__packet *p = vw__packet_new(dest, -1, stride);
    if (!p) return vw__world_error(w, VW_E_NOMEM, "out of memory posting a message");
    vw__msg_header *h = (vw__msg_header *)p->data;
    h->cell = cell;
    h->kind = (uint16_t)kind;
    h->size = (uint16_t)size;
    if (size) memcpy(p->data + sizeof *h, msg, size); /* (msg may be NULL then) */
    p->used = stride;
    p->nmsgs = 1;
    p->next = w->posted;
    w->posted = p;
    return VW_OK;
}

vw_status vw_world_run(vw_world *w)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    if (!w->committed) {
        vw_status st = vw_world_commit(w);
        if (st != VW_OK) return st;
    }
    return vw__runtime_run(w);
}

/* The module's done() on every cell's master, on the process hosting it, between runs;
   then agreed, so every process returns the same answer (the outer loop of an iterative
   solver stops on all processes alike). Every cell is asked, also after one said no: a
   module may keep per-cell tallies there. */
vw_status vw_world_done(vw_world *w, int *done)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    if (!done) return vw__world_error(w, VW_E_INVAL, "vw_world_done: done is NULL");
    *done = 0;
    if (!w->m->done)
        return vw__world_error(w, VW_E_INVAL, "vw_world_done: module '%s' has no done()", w->m->name);
    vw_status st = VW_OK;
    int all = 1;
    for (int c = 0; c < w->ncells; c++) {
        const vw__cell *cl = &w->cells[c];
        if (vw__worker_process(w, cl->worker) != w->rank) continue;
        if (!cl->built) {
            st = vw__world_error(w, VW_E_STATE, "vw_world_done: cell %d is not built (commit or "
                                 "run first)", c);
            break;
        }
        if (!vw__cell_done(w, c)) all = 0;
    }
    st = vw__world_step_agreed(w, st, "vw_world_done");
    if (st != VW_OK) return st;
    /* Not done anywhere is not done: one more agreement, its "failure" the answer. */
    if (w->transport) {
        char msg[8] = "";
        all = vw__world_agree(w, all ? VW_OK : VW_E_STATE, msg, sizeof msg) == VW_OK;
    }
    *done = all;
    return VW_OK;
}

/* ---- re-decomposition --------------------------------------------------------------- */

static vw_status redecompose(vw_world *w, const vw_decomp *d, const int *cell_worker)
{
    if (!d) return VW_E_INVAL;
    /* A bad mapping is refused before the old cells are torn down: found by map_cells
       after that, it left a world with no objects placed and its workers' cell lists
       from the old decomposition, whose next run called handlers without cell state. */
    for (int c = 0; cell_worker && c < vw_decomp_cell_count(d); c++)
        if (cell_worker[c] < 0 || cell_worker[c] >= w->gworkers)
            return vw__world_error(w, VW_E_INVAL, "mapping sends cell %d to worker %d of %d", c,
                                   cell_worker[c], w->gworkers);
    /* A message posted for the next run is delivered to its cell of the decomposition
       then in force (vw_world_post): that cell must still exist. */
    for (const vw__packet *p = w->posted; p; p = p->next) {
        int cell = ((const vw__msg_header *)p->data)->cell;
        if (cell >= vw_decomp_cell_count(d))
            return vw__world_error(w, VW_E_STATE, "a message posted to cell %d waits for the "
                                   "next run, and the new decomposition has %d cells", cell,
                                   vw_decomp_cell_count(d));
    }
    /* Which worker held each object before, to count migrations. */
    size_t n = w->nobjects;
    unsigned char *held = calloc(n ? n * (size_t)w->gworkers : 1, 1);
    if (!held) return VW_E_NOMEM;
    for (int c = 0; c < w->ncells; c++)
        for (size_t k = 0; k < w->cells[c].nobjs; k++)
            held[w->cells[c].objs[k] * (size_t)w->gworkers + (size_t)w->cells[c].worker] = 1;
    vw_decomp *nd;
    vw_status st = vw_decomp_clone(d, &nd);
    if (st != VW_OK) {
        free(held);
        return st;
    }
    free_cells(w);
    vw_decomp_free(w->decomp);
    w->decomp = nd;
    st = alloc_cells(w);
    if (st == VW_OK) st = map_cells(w, cell_worker);
    for (size_t i = 0; st == VW_OK && i < n; i++) st = place_object(w, i);
    uint64_t migrated = 0;
    for (int c = 0; st == VW_OK && c < w->ncells; c++)
        for (size_t k = 0; k < w->cells[c].nobjs; k++) {
            unsigned char *h = &held[w->cells[c].objs[k] * (size_t)w->gworkers + (size_t)w->cells[c].worker];
            if (!*h) migrated++;
            *h = 2; /* count each (object, worker) once */
        }
    free(held);
    w->migrated += migrated;
    w->committed = 0;
    return st;
}

vw_status vw_world_redecompose(vw_world *w, const vw_decomp *d, const int *cell_worker)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    return vw__world_step_agreed(w, redecompose(w, d, cell_worker), "vw_world_redecompose");
}

/* ---- duplicated cells --------------------------------------------------------------- */

int vw__replica_total(const vw_world *w)
{
    int n = 0;
    for (int c = 0; c < w->ncells; c++) n += w->cells[c].nreps;
    return n;
}

int vw__cell_rep_of(const vw_world *w, int cell, int worker)
{
    const vw__cell *c = &w->cells[cell];
    if (c->worker == worker) return 0;
    for (int r = 0; r < c->nreps; r++)
        if (c->reps[r].worker == worker) return r + 1;
    return -1;
}

/* The share pattern of a cell whose master is on worker `master` with copies on
   workers[0..k-1) (see vw__cell): of L = 16 k slots, unit u gets n_u in proportion to
   its worker's speed (largest remainders; at least one), laid out by smooth weighted
   round-robin so that each unit's slots are spread evenly. Equal speeds give the plain
   round-robin: unit u has slots u, u + k, u + 2k, ... Returns one block holding
   share_seq (L), share_pos (L) and share_first (k + 1), or NULL (out of memory). */
static int *make_shares(const vw_world *w, int master, const int *workers, int k)
{
    int L = 16 * k;
    int *blk = malloc(sizeof(int) * (size_t)(2 * L + k + 1));
    double *want = malloc(sizeof(double) * (size_t)k);
    long *cur = malloc(sizeof(long) * (size_t)k);
    if (!blk || !want || !cur) {
        free(blk), free(want), free(cur);
        return NULL;
    }
    int *seq = blk, *pos = blk + L, *first = blk + 2 * L, *n = first; /* n: counts, then offsets */
    /* As fractions of the fastest unit's speed, so the total is at most k: speeds of
       1e308 summed to infinity, L * speed / total was inf / inf, and the NaN cast to a
       count made a share of INT_MIN slots (a crash taking the first turn). */
    double total = 0, top = 0;
    for (int u = 0; u < k; u++) {
        int g = u ? workers[u - 1] : master;
        want[u] = w->speeds ? w->speeds[g] : 1.0;
        top = want[u] > top ? want[u] : top;
    }
    for (int u = 0; u < k; u++) {
        want[u] /= top;
        total += want[u];
    }
    int given = 0;
    for (int u = 0; u < k; u++) {
        want[u] = L * want[u] / total;
        n[u] = (int)want[u];
        want[u] -= n[u];
        given += n[u];
    }
    for (; given < L; given++) { /* the largest remainders (the lowest unit on ties) */
        int best = 0;
        for (int u = 1; u < k; u++)
            if (want[u] > want[best]) best = u;
        n[best]++;
        want[best] = -1;
    }
    for (int u = 0; u < k; u++)
        if (n[u] == 0) { /* a very slow worker still gets a slot, from the largest share */
            int big = 0;
            for (int v = 1; v < k; v++)
                if (n[v] > n[big]) big = v;
            n[big]--;
            n[u] = 1;
        }
    int even = 1;
    for (int u = 1; u < k; u++) even &= n[u] == n[0];
    for (int u = 0; u < k; u++) cur[u] = 0;
    for (int j = 0; j < L; j++) {
        /* Equal counts (equal speeds, every farmed cell): the round-robin the loop below
           would find, as the unit with the fewest turns so far and the lowest number
           is the one ahead; without the loop's k steps per slot, which made farming
           every cell to every worker cost cells x workers^2. */
        if (even) {
            seq[j] = j % k;
            continue;
        }
        int best = 0;
        for (int u = 0; u < k; u++) {
            cur[u] += n[u];
            if (cur[u] > cur[best]) best = u;
        }
        seq[j] = best;
        cur[best] -= L;
    }
    /* Counts to offsets (in place), then each unit's slots in ascending order (one pass
       over the slots, cur[u] counting those of unit u placed so far). */
    int off = 0;
    for (int u = 0; u <= k; u++) {
        int cnt = u < k ? n[u] : 0;
        first[u] = off;
        off += cnt;
    }
    for (int u = 0; u < k; u++) cur[u] = 0;
    for (int j = 0; j < L; j++) pos[first[seq[j]] + cur[seq[j]]++] = j;
    free(want);
    free(cur);
    return blk;
}

double vw__unit_share(const vw__cell *c, int u)
{
    if (!c->share_len) return 1.0;
    return (double)(c->share_first[u + 1] - c->share_first[u]) / c->share_len;
}

static vw_status set_replicas(vw_world *w, int cell, const int *workers, int n)
{
    if (cell < 0 || cell >= w->ncells || n < 0 || (n && !workers)) return VW_E_INVAL;
    vw__cell *c = &w->cells[cell];
    if (n) {
        int independent = 0;
        for (int k = 0; k < w->m->nkinds; k++) independent |= (w->m->kinds[k].flags & VW_MSG_INDEPENDENT) != 0;
        if (!independent)
            return vw__world_error(w, VW_E_INVAL, "module '%s' has no independent message kind, "
                                   "so its cells cannot be duplicated", w->m->name);
    }
    for (int i = 0; i < n; i++) {
        int bad = workers[i] < 0 || workers[i] >= w->gworkers || workers[i] == c->worker;
        for (int j = 0; j < i; j++) bad |= workers[j] == workers[i];
        if (bad)
            return vw__world_error(w, VW_E_INVAL, "cell %d cannot have a copy on worker %d", cell,
                                   workers[i]);
    }
    vw__replica *nr = vw__calloc_lines((size_t)(n ? n : 1), sizeof *nr);
    if (!nr) return VW_E_NOMEM;
    size_t nc = (size_t)(w->m->ncounters > 0 ? w->m->ncounters : 1);
    vw_status st = VW_OK;
    for (int i = 0; i < n && st == VW_OK; i++) {
        nr[i].worker = workers[i];
        nr[i].counters = vw__calloc_lines(nc, sizeof(int64_t));
        if (!nr[i].counters) st = VW_E_NOMEM;
    }
    unsigned *rr = n ? vw__calloc_lines((size_t)w->nworkers * VW__RR_STRIDE, sizeof *rr) : NULL;
    if (n && !rr) st = VW_E_NOMEM;
    int *shares = n && st == VW_OK ? make_shares(w, c->worker, workers, n + 1) : NULL;
    if (n && !shares) st = VW_E_NOMEM;
    if (st != VW_OK) {
        for (int i = 0; i < n; i++) free(nr[i].counters);
        free(nr);
        free(rr);
        return st;
    }
    for (int i = 0; i < n; i++)
        for (int r = 0; r < c->nreps; r++)
            if (c->reps[r].worker == workers[i]) {
                /* A copy that stays on its worker keeps its state and figures. */
                free(nr[i].counters);
                nr[i] = c->reps[r];
                c->reps[r].built = 0;
                c->reps[r].counters = NULL;
            }
    for (int r = 0; r < c->nreps; r++) free_replica(w, &c->reps[r]);
    free(c->reps);
    free(c->rr);
    c->rr = rr;
    c->reps = n ? nr : NULL;
    c->nreps = n;
    if (!n) free(nr);
    free(c->share_seq);
    c->share_len = n ? 16 * (n + 1) : 0;
    c->share_seq = shares;
    c->share_pos = shares ? shares + c->share_len : NULL;
    c->share_first = shares ? shares + 2 * c->share_len : NULL;
    w->committed = 0;
    w->units_stale = 1; /* listed by the next commit (vw_world.units_stale) */
    return VW_OK;
}

vw_status vw_world_set_replicas(vw_world *w, int cell, const int *workers, int n)
{
    if (!w) return VW_E_INVAL;
    vw__world_begin_step(w);
    return vw__world_step_agreed(w, set_replicas(w, cell, workers, n),
                                 "vw_world_set_replicas");
}

int vw_world_replicas(const vw_world *w, int cell, int *out, int max)
{
    if (!w || cell < 0 || cell >= w->ncells) return 0;
    const vw__cell *c = &w->cells[cell];
    for (int r = 0; r < c->nreps && r < max && out; r++) out[r] = c->reps[r].worker;
    return c->nreps;
}

/* ---- facts and measurements --------------------------------------------------------- */

/* A NULL world answers as world.h says (no rank, no workers, no decomposition), so a
   program that failed to create one can still print its figures. */
int vw_world_process(const vw_world *w) { return w ? w->rank : -1; }
int vw_world_processes(const vw_world *w) { return w ? w->nprocs : 0; }
int vw_world_workers(const vw_world *w) { return w ? w->nworkers : 0; }
int vw_world_is_output(const vw_world *w) { return w && w->rank == 0; }
const vw_decomp *vw_world_decomp(const vw_world *w) { return w ? w->decomp : NULL; }

int vw_world_cell_worker(const vw_world *w, int cell)
{
    return w && cell >= 0 && cell < w->ncells ? w->cell_worker[cell] : -1;
}

/* A failed query says why like a failed step. The message is not part of what the world
   computes (sqlite3_errmsg's is on a const handle too), hence the cast; from a callback,
   where workers share the world, the query leaves it alone. */
vw_status vw__world_query_error(const vw_world *w, vw_status st, const char *fmt, ...)
{
    if (atomic_load_explicit(&w->in_callbacks, memory_order_relaxed)) return st;
    va_list ap;
    va_start(ap, fmt);
    set_error((vw_world *)w, st, fmt, ap);
    va_end(ap);
    return st;
}

vw_status vw_world_cell_stats(const vw_world *w, int cell, vw_cell_stats *out)
{
    if (!w) return VW_E_INVAL;
    if (!out) return vw__world_query_error(w, VW_E_INVAL, "vw_world_cell_stats: out is NULL");
    if (cell < 0 || cell >= w->ncells)
        return vw__world_query_error(w, VW_E_INVAL, "vw_world_cell_stats: cell %d of %d", cell,
                                     w->ncells);
    const vw__cell *c = &w->cells[cell];
    out->worker = c->worker;
    out->objects = c->nobjs;
    out->messages_in = c->messages_in;
    out->busy_s = c->busy.s;
    out->load = c->busy.s;
    if (w->m->load && c->built && vw__worker_process(w, c->worker) == w->rank)
        out->load = vw__cell_load((vw_world *)w, cell);
    else if (w->m->load && w->nprocs > 1)
        out->load = c->load; /* the hosting process's figure at the last run's end */
    /* A duplicated cell's figures are the sums over its master and copies. */
    out->replicas = c->nreps;
    for (int r = 0; r < c->nreps; r++) {
        const vw__replica *rp = &c->reps[r];
        out->messages_in += rp->messages_in;
        out->busy_s += rp->busy.s;
        if (!w->m->load)
            out->load += rp->busy.s;
        else if (rp->built && vw__worker_process(w, rp->worker) == w->rank)
            out->load += vw__replica_load((vw_world *)w, cell, r + 1);
        else
            out->load += rp->load;
    }
    return VW_OK;
}

double vw_world_worker_busy(const vw_world *w, int g)
{
    if (!w || g < 0 || g >= w->gworkers) return 0;
    double s = 0;
    for (int c = 0; c < w->ncells; c++) {
        if (w->cells[c].worker == g) s += w->cells[c].busy.s;
        for (int r = 0; r < w->cells[c].nreps; r++)
            if (w->cells[c].reps[r].worker == g) s += w->cells[c].reps[r].busy.s;
    }
    return s;
}

int64_t vw_world_cell_counter(const vw_world *w, int cell, int idx)
{
    if (!w || cell < 0 || cell >= w->ncells || idx < 0 || idx >= w->m->ncounters) return 0;
    int64_t s = w->cells[cell].counters[idx];
    for (int r = 0; r < w->cells[cell].nreps; r++) s += w->cells[cell].reps[r].counters[idx];
    return s;
}

int64_t vw_world_worker_counter(const vw_world *w, int g, int idx)
{
    if (!w || idx < 0 || idx >= w->m->ncounters) return 0;
    int64_t s = 0;
    for (int c = 0; c < w->ncells; c++) {
        const vw__cell *cl = &w->cells[c];
        if (cl->worker == g) s += cl->counters[idx];
        for (int r = 0; r < cl->nreps; r++)
            if (cl->reps[r].worker == g) s += cl->reps[r].counters[idx];
    }
    return s;
}

int64_t vw_world_counter(const vw_world *w, int idx)
{
    int64_t s = 0;
    for (int c = 0; w && c < w->ncells; c++) s += vw_world_cell_counter(w, c, idx);
    return s;
}

double vw__lambda(const double *t, const double *speeds, int n)
{
    /* Speeds as fractions of the fastest, so their sum cannot overflow (1e308 each). */
    double top = 0;
    for (int g = 0; speeds && g < n; g++) {
        if (!(speeds[g] > 0) || !isfinite(speeds[g])) return INFINITY;
        top = speeds[g] > top ? speeds[g] : top;
    }
    double max = 0, sum = 0, ssum = 0;
    for (int g = 0; g < n; g++) {
        if (!(t[g] >= 0) || !isfinite(t[g])) return INFINITY;
        double s = speeds ? speeds[g] / top : 1.0, x = t[g] / s;
        sum += t[g];
        ssum += s;
        if (x > max) max = x;
    }
    return sum > 0 ? max / (sum / ssum) : 1.0;
}

/* The busy times are times already (a slower worker's are longer for the same work),
   so a worker's work is its busy time times its speed. */
double vw_world_imbalance(const vw_world *w)
{
    if (!w) return 0; /* never a lambda, which is at least 1 */
    if (w->gworkers < 1) return 1.0;
    double *t = malloc(sizeof *t * (size_t)w->gworkers);
    if (!t) return 0;
    double top = 0;
    for (int g = 0; w->speeds && g < w->gworkers; g++) top = w->speeds[g] > top ? w->speeds[g] : top;
    for (int g = 0; g < w->gworkers; g++)
        t[g] = vw_world_worker_busy(w, g) * (w->speeds ? w->speeds[g] / top : 1.0);
    double lam = vw__lambda(t, w->speeds, w->gworkers);
    free(t);
    return lam;
}

void vw_world_reset_stats(vw_world *w)
{
    if (!w) return;
    vw__world_guard(w, "vw_world_reset_stats"); /* the workers write these figures */
    for (int c = 0; c < w->ncells; c++) {
        w->cells[c].busy.s = 0;
        w->cells[c].messages_in = 0;
        memset(w->cells[c].counters, 0, sizeof(int64_t) * (size_t)(w->m->ncounters > 0 ? w->m->ncounters : 1));
        for (int r = 0; r < w->cells[c].nreps; r++) {
            vw__replica *rp = &w->cells[c].reps[r];
            rp->busy.s = 0;
            rp->messages_in = 0;
            memset(rp->counters, 0, sizeof(int64_t) * (size_t)(w->m->ncounters > 0 ? w->m->ncounters : 1));
        }
    }
    for (int i = 0; i < w->nworkers; i++) {
        vw__worker *wk = &w->workers[i];
        wk->busy_s = 0;
        wk->msgs_sent = wk->bytes_sent = wk->packets_sent = 0;
        wk->msgs_remote = wk->bytes_remote = wk->turns_remote = 0;
        wk->tr_self_msgs = wk->tr_self_bytes = 0;
        if (wk->tr_proc) memset(wk->tr_proc, 0, 2 * sizeof *wk->tr_proc * (size_t)w->nprocs);
    }
    memset(w->wstats, 0, sizeof *w->wstats * (size_t)w->gworkers);
}

/* Names are kept whole and phases are not counted: a name cut to a fixed size, or a
   phase past a fixed number, was dropped without a word and vw_world_time said 0. */
void vw_world_add_time(vw_world *w, const char *phase, double seconds)
{
    if (!w || !phase) return;
    for (int i = 0; i < w->nphases; i++)
        if (strcmp(w->phases[i].name, phase) == 0) {
            w->phases[i].s += seconds;
            return;
        }
    if (w->nphases == w->capphases) {
        int cap = w->capphases ? 2 * w->capphases : 8;
        struct vw__phase *p = realloc(w->phases, sizeof *p * (size_t)cap);
        if (!p) return; /* (a time is not worth failing the caller for) */
        w->phases = p;
        w->capphases = cap;
    }
    char *name = strdup(phase);
    if (!name) return;
    w->phases[w->nphases].name = name;
    w->phases[w->nphases++].s = seconds;
}

double vw_world_time(const vw_world *w, const char *phase)
{
    for (int i = 0; w && phase && i < w->nphases; i++)
        if (strcmp(w->phases[i].name, phase) == 0) return w->phases[i].s;
    return 0;
}

void vw_world_set_balance_info(vw_world *w, const char *strategy, double before, double after,
                               uint64_t migrated)
{
    if (!w) return;
    snprintf(w->balance_strategy, sizeof w->balance_strategy, "%s", strategy ? strategy : "none");
    w->imbalance_before = before;
    w->imbalance_after = after;
    w->migrated = migrated;
}

uint64_t vw_world_migrated(const vw_world *w) { return w ? w->migrated : 0; }

/* The program's own agreement (engine.h), in both engines. From a callback it would be
   a collective made by a worker thread in the middle of a run or a build, beside the
   runtime's own collectives (under MPI a hang, or agreements mixed up with each other;
   MPI_THREAD_FUNNELED forbids it outright): refused as the calls that change the world
   are, though it changes nothing. */
vw_status vw_world_agree(vw_world *w, vw_status local, char *msg, size_t len)
{
    if (!w) return VW_E_INVAL;
    vw__world_guard(w, "vw_world_agree");
    return vw__world_agree(w, local, msg, len);
}

/* ---- without MPI: the engine is this one process ------------------------------------ */

#if !VW_HAVE_MPI

vw_status vw__mpi_attach(vw_world *w)
{
    (void)w;
    return VW_OK;
}

int vw__mpi_first_differing(vw_world *w, uint64_t v)
{
    (void)w, (void)v;
    return -1;
}

int vw__mpi_first_differing_n(vw_world *w, const uint64_t *v, int n, int *part, uint64_t *theirs,
                              uint64_t *first)
{
    (void)w, (void)v, (void)n, (void)part, (void)theirs, (void)first;
    return -1;
}

vw_status vw__mpi_fetch_records(vw_world *w, vw_status local, const uint64_t *ask,
                                size_t nask, unsigned char **got, char *msg, size_t len)
{
    /* One process keeps every record: nothing is ever asked. */
    (void)w, (void)ask, (void)msg, (void)len;
    *got = NULL;
    return local == VW_OK && nask ? VW_E_STATE : local;
}

int vw_engine_launched(void) { return 0; }
vw_status vw_engine_init(int *argc, char ***argv, char *msg, size_t len)
{
    (void)argc, (void)argv;
    if (msg && len) msg[0] = 0;
    return VW_OK;
}
void vw_engine_finish(void) {}
void vw_engine_abort(int status, const char *msg)
{
    if (msg) fprintf(stderr, "%s\n", msg);
    fflush(NULL);
    _exit(status ? status : 1);
}
int vw_engine_rank(void) { return 0; }
int vw_engine_size(void) { return 1; }
vw_status vw_engine_agree(vw_status local, char *msg, size_t len)
{
    (void)msg, (void)len;
    return local;
}
vw_status vw__world_agree(vw_world *w, vw_status local, char *msg, size_t len)
{
    (void)w, (void)msg, (void)len;
    return local;
}
vw_status vw_config_agree(const vw_config *c, vw_status local, char *msg, size_t len)
{
    (void)c, (void)msg, (void)len;
    return local;
}
void vw_engine_broadcast(void *buf, size_t n) { (void)buf, (void)n; }
double vw_engine_core_share(void) { return vw_host_cores(); }
int vw_engine_workers(int workers)
{
    if (workers < 0 || workers > VW__MAX_WORKERS) return -1; /* vw_world_create refuses it */
    return workers > 0 ? workers : vw_host_cores();
}
#endif
